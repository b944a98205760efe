//! `neurotex datasets` and `neurotex benchmark` through the binary: the list, a recipe
//! checked, a folder's digest, FabricSlide fetched from `../shared` into a cache, and the
//! errors a user meets (an unknown name, a bad recipe, a dataset not fetched, `--from` with
//! two datasets).

use crate::util::{s, Dir};

#[test]
fn list_check_digest_and_the_errors_a_user_meets() {
    let dir = Dir::new();
    let cache = dir.join("cache");
    let list = dir.ok(&["datasets", "list", "--cache", s(&cache)]);
    assert!(
        list.contains("fabricslide") && list.contains("not fetched"),
        "{list}"
    );
    let check = dir.ok(&["datasets", "check", "fabricslide"]);
    assert!(check.contains("a valid recipe"), "{check}");
    let err = dir.fails(&["datasets", "check", "fabricslid"]);
    assert!(err.contains("known: fabricslide"), "{err}");
    std::fs::write(
        dir.join("bad.toml"),
        "name = \"x\"\ntitle = \"t\"\nsize = 3\n",
    )
    .unwrap();
    let err = dir.fails(&["datasets", "check", "bad.toml"]);
    assert!(err.contains("bad.toml") && err.contains("size"), "{err}");
    let err = dir.fails(&["datasets", "path", "fabricslide", "--cache", s(&cache)]);
    assert!(err.contains("datasets fetch fabricslide`"), "{err}");
    std::fs::create_dir_all(dir.join("tree")).unwrap();
    std::fs::write(dir.join("tree/a.csv"), "1\n").unwrap();
    let digest = dir.ok(&["datasets", "digest", "tree"]);
    assert!(digest.starts_with("tree-sha256 = \""), "{digest}");
    let digest = dir.ok(&["datasets", "digest", "tree/a.csv"]);
    assert!(
        digest.contains(
            "sha256 = \"4355a46b19d348dc2f57c046f8ef63d4538ebb936000f3c9ee954a27460dd865\""
        ) && digest.contains("size = 2"),
        "{digest}"
    );
    // Every recipe is checked before anything runs: a bad one names its file, and --from
    // (one dataset's copy) with two datasets is refused.
    let err = dir.fails(&["benchmark", "fabricslide", "bad.toml", "--out", "o"]);
    assert!(err.contains("bad.toml"), "{err}");
    let two = [
        "benchmark",
        "fabricslide",
        "fabricslide",
        "--out",
        "o",
        "--from",
        "tree",
    ];
    let err = dir.fails(&two);
    assert!(err.contains("--from"), "{err}");
    assert!(!dir.join("o").exists());
}

#[test]
fn fabricslide_is_fetched_from_the_shared_copy_and_found_again() {
    let copy = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/fabricslide/fabric");
    if !copy.is_dir() {
        eprintln!("skipped: no ../shared/data/fabricslide");
        return;
    }
    let dir = Dir::new();
    let cache = dir.join("cache");
    let fetched = dir.ok(&[
        "datasets",
        "fetch",
        "fabricslide",
        "--from",
        s(&copy),
        "--cache",
        s(&cache),
    ]);
    let path = dir.ok(&["datasets", "path", "fabricslide", "--cache", s(&cache)]);
    assert_eq!(fetched, path);
    let manifest =
        std::fs::read_to_string(std::path::Path::new(path.trim()).join("manifest.csv")).unwrap();
    assert_eq!(manifest.lines().count(), 967);
    let list = dir.ok(&["datasets", "list", "--cache", s(&cache)]);
    assert!(
        list.contains("fetched ") && !list.contains("not fetched"),
        "{list}"
    );
}
