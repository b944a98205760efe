//! Records the git commit neurotex is built from, when it is built from a checkout, so
//! results and models can say which code made them (`NEUROTEX_GIT_COMMIT`, empty otherwise).

use std::process::Command;

fn main() {
    let commit = Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    println!("cargo:rustc-env=NEUROTEX_GIT_COMMIT={commit}");
    // A new commit changes HEAD (a detached checkout) or the branch's ref.
    for path in ["../../.git/HEAD", "../../.git/refs/heads"] {
        println!("cargo:rerun-if-changed={path}");
    }
}
