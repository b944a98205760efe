//! `neurotex simulate`.

use crate::util::{s, Dir};

#[test]
fn simulate_writes_a_dataset_the_pipeline_reads() {
    let dir = Dir::new();
    let out = dir.join("sim");
    dir.ok(&[
        "simulate",
        "--out",
        s(&out),
        "--trials",
        "5",
        "--speeds",
        "15",
        "--textures",
        "CP,RT",
    ]);
    let manifest = std::fs::read_to_string(out.join("manifest.csv")).unwrap();
    assert!(manifest.starts_with("file,label,speed_mm_s,force_n,trial,slide_start_s,slide_end_s\n"));
    assert_eq!(manifest.lines().count(), 11);
    assert_eq!(dir.evaluate_json(&out, "glcm3d", &[])["n"], 10);
    let err = dir.fails(&["simulate", "--out", s(&out), "--trials", "5"]);
    assert!(err.contains("not empty"), "{err}");
    let (x, y) = (dir.join("x"), dir.join("y"));
    let err = dir.fails(&["simulate", "--out", s(&x), "--textures", "FT9"]);
    assert!(
        err.contains("`textures`") && err.contains("got FT9"),
        "{err}"
    );
    let err = dir.fails(&["simulate", "--out", s(&y), "--speeds", "0"]);
    assert!(err.contains("positive"), "{err}");
    let err = dir.fails(&["simulate", "--out", s(&y), "--trials", "0"]);
    assert!(err.contains("trials must be between 1 and 10000"), "{err}");
    assert!(!x.exists() && !y.exists());
}
