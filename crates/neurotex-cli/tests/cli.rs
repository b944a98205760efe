//! The real `neurotex` binary on small datasets written in temporary folders: outputs,
//! JSON keys, and bad input (clear message, non-zero exit, no output file). One module per
//! subcommand; `util` runs the binary and writes the datasets.

mod atomic;
mod classifiers;
mod compare;
mod conditions;
mod datasets;
mod encode;
mod evaluate;
mod events;
mod extensions;
mod features;
mod foreign_nir;
mod hostile;
mod import;
mod inspect;
mod model;
mod outputs;
mod raw_logs;
mod reproduce;
mod simulate;
mod stream;
mod trust;
mod util;
mod xylo;

use util::Dir;

#[test]
fn help_explains_the_commands() {
    let dir = Dir::new();
    let text = dir.ok(&["--help"]);
    for cmd in [
        "encode",
        "features",
        "evaluate",
        "simulate",
        "reproduce",
        "import",
        "train",
        "predict",
        "stream",
    ] {
        assert!(text.contains(cmd), "{text}");
    }
    let text = dir.ok(&["evaluate", "--help"]);
    assert!(
        text.contains("--train-speeds") && text.contains("mean over taxels"),
        "{text}"
    );
    let text = dir.ok(&["import", "csv", "--help"]);
    assert!(
        text.contains("ROWSxCOLS")
            && text.contains("row,col;row,col")
            && text.contains("`ms`, `s` or `us`"),
        "{text}"
    );
}
