//! The numbers docs/results.md quotes from FabricSlide come from the run that
//! docs/results/fabricslide.json records (cut from its results.json by
//! `tools/results_summary.py`): the table is rendered here from that file and must appear in
//! the page as it is, and so must the E3 sentence. `NEUROTEX_BLESS=1` writes the rendered
//! table into the page, after a new run.

use std::path::PathBuf;

use serde_json::Value;

fn docs() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs")
}

fn pct(v: &Value) -> String {
    format!("{:.1}", 100.0 * v.as_f64().expect("a number"))
}

fn with_interval(value: &Value, interval: &Value) -> String {
    format!(
        "{} [{}, {}]",
        pct(value),
        pct(&interval["lower"]),
        pct(&interval["upper"])
    )
}

/// The speeds of an analysis, as written in the file, in ascending numeric order.
fn speeds(analysis: &Value) -> Vec<String> {
    let mut keys: Vec<String> = analysis
        .as_object()
        .expect("speeds")
        .keys()
        .cloned()
        .collect();
    keys.sort_by(|a, b| {
        let (a, b): (f64, f64) = (a.parse().unwrap(), b.parse().unwrap());
        a.total_cmp(&b)
    });
    keys
}

/// The table of docs/results.md: E1, E4's 2D-GLCM and E6 per velocity.
fn table(run: &Value) -> String {
    let mut out = String::from(
        "| velocity (mm/s) | single taxel, mean (%) | best taxel, after the fact (%) | 2D-GLCM (%) | 3D-GLCM (%) | E6, held out: single / 3D-GLCM (%) |\n|---|---|---|---|---|---|\n",
    );
    for s in speeds(&run["e1"]) {
        let (e1, e4, e6) = (&run["e1"][&s], &run["e4"][&s], &run["e6"][&s]);
        out.push_str(&format!(
            "| {s} | {} | {} ({}) | {} | {} | {} / {} |\n",
            with_interval(&e1["taxel_mean"], &e1["taxel_mean_interval"]),
            pct(&e1["taxel_best"]),
            e1["taxel_best_cell"].as_str().unwrap(),
            with_interval(&e4["glcm2d"], &e4["glcm2d_interval"]),
            with_interval(&e1["glcm3d"], &e1["glcm3d_interval"]),
            pct(&e6["taxel_mean"]),
            pct(&e6["glcm3d"]),
        ));
    }
    out
}

/// The E3 sentence's numbers: unperturbed and with every taxel moved.
fn e3_sentence(run: &Value) -> String {
    let e3 = &run["e3"];
    let (n, mean) = (e3["n"].as_array().unwrap(), e3["mean"].as_array().unwrap());
    format!(
        "E3 at {} mm/s: 3D-GLCM {} % unperturbed (the encoding as run), {} % with all {} taxels\nmoved.",
        e3["speed"].as_f64().unwrap(),
        pct(&e3["glcm3d"]),
        pct(mean.last().unwrap()),
        n.last().unwrap()
    )
}

#[test]
fn fabricslide_numbers_in_the_docs_are_those_of_the_recorded_run() {
    let run: Value = serde_json::from_str(
        &std::fs::read_to_string(docs().join("results/fabricslide.json")).unwrap(),
    )
    .unwrap();
    let page_path = docs().join("results.md");
    let mut page = std::fs::read_to_string(&page_path).unwrap();
    let rendered = table(&run);
    if std::env::var_os("NEUROTEX_BLESS").is_some() {
        let start = page
            .find("| velocity (mm/s) |")
            .expect("the table's header");
        let end = start
            + page[start..]
                .find("\n\n")
                .expect("a blank line after the table")
            + 1;
        page.replace_range(start..end, &rendered);
        std::fs::write(&page_path, &page).unwrap();
    }
    assert!(
        page.contains(&rendered),
        "docs/results.md's FabricSlide table is not the one docs/results/fabricslide.json gives:\n{rendered}"
    );
    let sentence = e3_sentence(&run);
    assert!(page.contains(&sentence), "{sentence}");
    assert_eq!(run["recordings"], 966);
    assert!(
        page.contains(&format!("all {}", run["recordings"])),
        "the page names the recordings the run had"
    );
    // The page names the run the numbers come from.
    let command = run["command"].as_str().unwrap();
    assert!(
        page.contains(&format!("`{command}`"))
            || page.contains(command.split(" --out").next().unwrap())
    );
}
