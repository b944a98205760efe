//! Dataset recipes, fetching into the cache, and the benchmark: recipes refused with their
//! key named; fabricated archives (headerless CSV logs in a zip, a stacked array in a
//! tar.gz) fetched, verified and imported; a damaged or hostile archive refused with the
//! cache left as it was; the tree digest against coreutils' `sha256sum`; and the
//! leaderboard equal to `compare --nested` on the same folds.

use std::io::Write;
use std::path::{Path, PathBuf};

use neurotex::compare::Comparison;
use neurotex::datasets::{self, fetch, tree_digest, Recipe};
use neurotex::options::StageOptions;
use neurotex::progress::silent;
use neurotex::workflows::benchmark::BenchmarkOptions;
use neurotex::workflows::compare::CompareOptions;
use neurotex::workflows::{KnnOptions, OpenOptions, SnnOptions};
use sha2::{Digest, Sha256};

use crate::support::XorShift;

/// The textures, speeds and trials of the fabricated logs.
const TEXTURES: [&str; 3] = ["silk", "denim", "cork"];
const SPEEDS: [u32; 2] = [10, 30];
const TRIALS: usize = 6;

/// One headerless log: 8 channels first, the time in ms last, 100 Hz for 3 s; each texture
/// a ridge spacing the slide turns into a frequency, with noise.
fn log(texture: usize, speed: u32, trial: usize) -> String {
    let mut rng = XorShift::new((texture * 1000 + speed as usize * 10 + trial) as u64 + 7);
    let spacing_mm = [0.8, 1.6, 3.2][texture];
    let mut out = String::new();
    for i in 0..300 {
        let t = i as f64 / 100.0;
        for c in 0..8 {
            let phase = 2.0 * std::f64::consts::PI * (speed as f64 * t / spacing_mm) + c as f64;
            let v = 500.0
                + 200.0 * (1.0 + phase.sin()) * (1.0 + 0.2 * c as f64)
                + 40.0 * rng.fraction(1000);
            out.push_str(&format!("{v:.1},"));
        }
        out.push_str(&format!("{}\n", i * 10));
    }
    out
}

/// A zip of the fabricated logs under `folder/` (and `extra` entries), its bytes.
fn logs_zip(folder: &str, extra: &[(&str, &str)]) -> Vec<u8> {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default();
    for (k, name) in TEXTURES.iter().enumerate() {
        for &speed in &SPEEDS {
            for trial in 0..TRIALS {
                zip.start_file(format!("{folder}/{name}_v{speed}_{trial}.csv"), options)
                    .unwrap();
                zip.write_all(log(k, speed, trial).as_bytes()).unwrap();
            }
        }
    }
    for (name, text) in extra {
        zip.start_file(*name, options).unwrap();
        zip.write_all(text.as_bytes()).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// SHA-256 in hex, by the `sha2` crate directly.
fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The recipe of the headerless logs in `archive` (`logs.zip`), with `conditions` as the
/// speed values it lists.
fn headerless_recipe(archive: &[u8], conditions: &str) -> String {
    format!(
        r#"
name = "ridges"
title = "Three fabricated ridged textures, 8 taxels, headerless logs"
citation = "neurotex's tests"
licence = "MIT"

[[source]]
url = "https://example.org/data/logs.zip"
kind = "zip"
sha256 = "{}"
size = {}
folder = "logs"

[import]
kind = "csv"
no-header = true
time-column = "8"
channels = "0-7"
grid = "2x4"
name-pattern = "{{label}}_v{{speed}}_{{trial}}.csv"

[conditions]
speed_mm_s = [{conditions}]

[[protocol]]
id = "within-speed"
per = "speed_mm_s"

[[protocol]]
id = "speed-held-out"
hold-out = "speed_mm_s"

[[published]]
accuracy = 0.9
protocol = "a method of another paper"
citation = "Someone 2024"
beside = "within-speed"
same-protocol = false
"#,
        sha256(archive),
        archive.len()
    )
}

/// A fresh folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("neurotex-datasets-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// What `dir` holds, as sorted relative paths.
fn listing(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    if let Ok(items) = std::fs::read_dir(dir) {
        for item in items.flatten() {
            out.push(item.file_name().to_string_lossy().into_owned());
        }
    }
    out.sort();
    out
}

#[test]
fn the_built_in_recipes_parse_and_fabricslide_names_its_two_protocols() {
    let recipes = datasets::built_in();
    let fs = recipes.iter().find(|r| r.name == "fabricslide").unwrap();
    let ids: Vec<&str> = fs.protocols.iter().map(|p| p.id.as_str()).collect();
    assert_eq!(ids, ["within-velocity", "velocity-held-out"]);
    assert_eq!(fs.published[0].accuracy, 0.96);
    assert!(!fs.published[0].same_protocol);
    // The digest naming its cache entry and keying its kept comparisons: a new optional
    // key of the recipe format must not change it, or every fetched copy is fetched anew.
    assert!(
        fs.import_digest().starts_with("65d647c0dafb"),
        "{}",
        fs.import_digest()
    );
}

#[test]
fn recipes_breaking_a_rule_are_refused_naming_the_key() {
    let good = headerless_recipe(b"x", r#""10", "30""#);
    let cases = [
        (
            good.replace("licence = \"MIT\"", "licence = \"MIT\"\ncolour = \"red\""),
            "colour",
        ),
        (good.replace("sha256 = ", "# sha256 = "), "missing checksum"),
        (good.replace("grid = \"2x4\"", "grid = \"2by4\""), "grid"),
        (
            good.replace("per = \"speed_mm_s\"", "per = \"force_n\""),
            "force_n",
        ),
        (
            good.replace("beside = \"within-speed\"", "beside = \"pooled\""),
            "pooled",
        ),
        (
            good.replace("accuracy = 0.9", "accuracy = 90"),
            "accuracy = 90",
        ),
        (good.replace("kind = \"zip\"", "kind = \"rar\""), "rar"),
        (
            good.replace("name = \"ridges\"", "name = \"Ridges!\""),
            "Ridges!",
        ),
        (
            good.replace(
                "time-column = \"8\"",
                "time-column = \"8\"\ntime-colum = \"8\"",
            ),
            "time-colum",
        ),
    ];
    for (text, named) in cases {
        let err = Recipe::parse(&text, Path::new("r.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(named) && err.contains("r.toml"),
            "{named}: {err}"
        );
    }
    Recipe::parse(&good, Path::new("r.toml")).unwrap();
}

#[test]
fn each_rule_of_a_recipe_is_its_own_error() {
    use neurotex::datasets::{RecipeError as E, SourceRule as S};
    let good = headerless_recipe(b"x", r#""10", "30""#);
    let broken = |from: &str, to: &str| -> E {
        assert!(good.contains(from), "{from}");
        let recipe: Recipe = toml::from_str(&good.replacen(from, to, 1)).unwrap();
        recipe.check().unwrap_err()
    };
    assert!(
        matches!(broken("name = \"ridges\"", "name = \"Ridges\""), E::Name(n) if n == "Ridges")
    );
    let source = |e: E| match e {
        E::Source { index: 1, rule, .. } => rule,
        other => panic!("{other}"),
    };
    assert_eq!(source(broken("sha256 = ", "# sha256 = ")), S::Checksum);
    assert_eq!(
        source(broken("https://example.org", "ftp://example.org")),
        S::Url
    );
    assert!(matches!(
        source(broken("sha256 = \"", "sha256 = \"ABC")),
        S::Hex { key: "sha256", .. }
    ));
    assert_eq!(
        source(broken("kind = \"zip\"", "kind = \"git-archive\"")),
        S::TreeDigest
    );
    let twice = good.replacen(
        "[import]",
        &format!(
            "{}\n[import]",
            &good[good.find("[[source]]").unwrap()..good.find("[import]").unwrap()]
        ),
        1,
    );
    let recipe: Recipe = toml::from_str(&twice).unwrap();
    assert!(
        matches!(recipe.check().unwrap_err(), E::Source { index: 2, rule: S::SameName(n), .. } if n == "logs.zip")
    );
    assert!(
        matches!(broken("grid = \"2x4\"", "grid = \"2by4\""), E::Import { key, .. } if key == "grid")
    );
    assert!(
        matches!(broken("per = \"speed_mm_s\"", "per = \"force_n\""), E::ProtocolConditions { column, .. } if column == "force_n")
    );
    assert!(
        matches!(broken("per = \"speed_mm_s\"", "per = \"speed_mm_s\"\nhold-out = \"speed_mm_s\""), E::ProtocolKind(id) if id == "within-speed")
    );
    assert!(
        matches!(broken("id = \"speed-held-out\"", "id = \"within-speed\""), E::ProtocolId(id) if id == "within-speed")
    );
    assert!(
        matches!(broken("beside = \"within-speed\"", "beside = \"pooled\""), E::PublishedBeside { beside, .. } if beside == "pooled")
    );
    assert!(
        matches!(broken("accuracy = 0.9", "accuracy = 1.5"), E::PublishedAccuracy { accuracy, .. } if accuracy == 1.5)
    );
}

#[test]
fn the_tree_digest_is_that_of_sha256sum_over_the_sorted_files() {
    let dir = scratch("tree");
    std::fs::create_dir_all(dir.join("b/c")).unwrap();
    std::fs::write(dir.join("a.csv"), "1,2\n").unwrap();
    std::fs::write(dir.join("b/c/d.csv"), "3,4\n").unwrap();
    std::fs::write(dir.join("B.csv"), "").unwrap();
    let script =
        "find . -type f | sed 's|^\\./||' | LC_ALL=C sort | xargs -d '\\n' sha256sum | sha256sum";
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(script)
        .current_dir(&dir)
        .output();
    let Some(out) = out.ok().filter(|o| o.status.success()) else {
        eprintln!("skipped: no sh, find or sha256sum here");
        return;
    };
    let want = String::from_utf8(out.stdout).unwrap();
    assert_eq!(
        tree_digest(&dir).unwrap(),
        want.split_whitespace().next().unwrap()
    );
}

#[test]
fn a_zip_of_headerless_logs_is_verified_imported_once_and_reused() {
    let dir = scratch("zip");
    let archive = logs_zip("logs", &[]);
    std::fs::create_dir_all(dir.join("copy")).unwrap();
    std::fs::write(dir.join("copy/logs.zip"), &archive).unwrap();
    let recipe = Recipe::parse(
        &headerless_recipe(&archive, r#""10", "30""#),
        Path::new("r.toml"),
    )
    .unwrap();
    let cache = dir.join("cache");
    let dataset = fetch(&recipe, &cache, Some(&dir.join("copy")), &silent).unwrap();
    let opened = neurotex::recording::Dataset::open(&dataset).unwrap();
    assert_eq!(opened.entries.len(), TEXTURES.len() * SPEEDS.len() * TRIALS);
    assert_eq!(
        opened.entries[0]
            .field("speed_mm_s")
            .as_deref()
            .map(|s| s == "10" || s == "30"),
        Some(true)
    );
    // Fetched before: reused without the copy.
    assert_eq!(fetch(&recipe, &cache, None, &silent).unwrap(), dataset);
    assert_eq!(datasets::fetched(&cache, &recipe), Some(dataset.clone()));
    // The same sources and import with a condition the data lacks: refused on reuse too.
    let edited = headerless_recipe(&archive, r#""10", "20", "30""#);
    let edited = Recipe::parse(&edited, Path::new("r.toml")).unwrap();
    let err = fetch(&edited, &cache, None, &silent)
        .unwrap_err()
        .to_string();
    assert!(err.contains("speed_mm_s = 20"), "{err}");
    assert!(dataset.is_dir());
}

#[test]
fn a_damaged_archive_a_zip_slip_a_zip_bomb_or_a_missing_condition_leaves_the_cache_as_it_was() {
    let dir = scratch("refused");
    std::fs::create_dir_all(dir.join("copy")).unwrap();
    let cache = dir.join("cache");
    let good = logs_zip("logs", &[]);
    // `archive` as the copy's logs.zip, fetched with the recipe `text`: the error.
    let refused = |archive: &[u8], text: &str| -> String {
        std::fs::write(dir.join("copy/logs.zip"), archive).unwrap();
        let recipe = Recipe::parse(text, Path::new("r.toml")).unwrap();
        let err = fetch(&recipe, &cache, Some(&dir.join("copy")), &silent).unwrap_err();
        err.to_string()
    };
    // One byte changed.
    let mut damaged = good.clone();
    let last = damaged.len() - 30;
    damaged[last] ^= 1;
    let err = refused(&damaged, &headerless_recipe(&good, r#""10", "30""#));
    assert!(
        err.contains("recipe ridges") && err.contains("logs.zip") && err.contains("SHA-256"),
        "{err}"
    );
    assert!(listing(&cache).is_empty(), "{:?}", listing(&cache));
    // An entry that would land outside its folder.
    let hostile = logs_zip("logs", &[("logs/../../escaped.csv", "1,2\n")]);
    let err = refused(&hostile, &headerless_recipe(&hostile, r#""10", "30""#));
    assert!(
        err.contains("escaped.csv") && err.contains("outside"),
        "{err}"
    );
    assert!(listing(&cache).is_empty() && !anywhere(&dir, "escaped.csv"));
    // A small archive that inflates past what its recipe allows (a "zip bomb").
    let zeros = "0".repeat(2_000_000);
    let bomb = logs_zip("logs", &[("logs/zeros.txt", &zeros)]);
    assert!(bomb.len() < good.len() + 20_000, "{}", bomb.len());
    let text = headerless_recipe(&bomb, r#""10", "30""#).replace(
        "folder = \"logs\"",
        "folder = \"logs\"\nunpacked-at-most = 1000000",
    );
    let err = refused(&bomb, &text);
    assert!(
        err.contains("more than 1000000 bytes") && err.contains("zeros.txt"),
        "{err}"
    );
    assert!(listing(&cache).is_empty() && !anywhere(&dir, "zeros.txt"));
    // A condition the data does not have, named by the copy the data came from, not by
    // the cache entry that was rolled back.
    let lacking = headerless_recipe(&good, r#""10", "20""#);
    let err = refused(&good, &lacking);
    assert!(err.contains("speed_mm_s = 20"), "{err}");
    assert!(
        err.contains(&dir.join("copy").display().to_string()),
        "{err}"
    );
    assert!(!err.contains(&cache.display().to_string()), "{err}");
    assert!(listing(&cache).is_empty());
    let recipe = Recipe::parse(&lacking, Path::new("r.toml")).unwrap();
    // No copy given and no such file to download: the message names the source, and the
    // cache is left as it was.
    let err = fetch(&recipe, &cache, None, &silent)
        .unwrap_err()
        .to_string();
    assert!(err.contains("https://example.org/data/logs.zip"), "{err}");
    assert!(listing(&cache).is_empty(), "{:?}", listing(&cache));
}

/// A local HTTP server for one file: `GET /data/logs.zip` gets `bytes` (from the offset a
/// `Range: bytes=N-` header asks, with 206), any other path 404. The first `cut` answers
/// stop after half the bytes they promised. Returns its address and the Range headers seen.
fn serve(bytes: Vec<u8>, cut: usize) -> (String, std::sync::Arc<std::sync::Mutex<Vec<String>>>) {
    use std::io::{BufRead, BufReader};
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let address = format!("http://{}", listener.local_addr().unwrap());
    let ranges = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let seen = ranges.clone();
    std::thread::spawn(move || {
        for (i, stream) in listener.incoming().enumerate() {
            let Ok(mut stream) = stream else { continue };
            let mut reader = BufReader::new(stream.try_clone().unwrap());
            let (mut first, mut from, mut asked) = (String::new(), 0usize, "none".to_string());
            reader.read_line(&mut first).unwrap();
            loop {
                let mut line = String::new();
                if reader.read_line(&mut line).unwrap() == 0 || line == "\r\n" {
                    break;
                }
                if let Some(r) = line.to_ascii_lowercase().strip_prefix("range: bytes=") {
                    asked = r.trim().to_string();
                    from = r.trim().trim_end_matches('-').parse().unwrap();
                }
            }
            if !first.starts_with("GET /data/logs.zip ") {
                let _ = stream.write_all(
                    b"HTTP/1.1 404 Not Found\r\ncontent-length: 0\r\nconnection: close\r\n\r\n",
                );
                continue;
            }
            seen.lock().unwrap().push(asked);
            let body = &bytes[from..];
            let (n, last) = (bytes.len(), bytes.len() - 1);
            let status = if from > 0 {
                format!("206 Partial Content\r\ncontent-range: bytes {from}-{last}/{n}")
            } else {
                "200 OK".to_string()
            };
            let head = format!(
                "HTTP/1.1 {status}\r\ncontent-length: {}\r\nconnection: close\r\n\r\n",
                body.len()
            );
            let _ = stream.write_all(head.as_bytes());
            let end = if i < cut { body.len() / 2 } else { body.len() };
            let _ = stream.write_all(&body[..end]);
        }
    });
    (address, ranges)
}

#[test]
fn sources_are_downloaded_and_an_interrupted_download_resumes() {
    let dir = scratch("download");
    let cache = dir.join("cache");
    let archive = logs_zip("logs", &[]);
    let (address, ranges) = serve(archive.clone(), 1);
    let text =
        headerless_recipe(&archive, r#""10", "30""#).replace("https://example.org", &address);
    let recipe = Recipe::parse(&text, Path::new("r.toml")).unwrap();
    // The first answer stops halfway: an error, the part kept, no cache entry.
    let err = fetch(&recipe, &cache, None, &silent)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("run again to resume") && err.contains(&address),
        "{err}"
    );
    let entry = datasets::fetch::entry(&cache, &recipe);
    assert!(!entry.exists());
    // Run again: the rest is asked for from where the part stops, and the fetch succeeds.
    let dataset = fetch(&recipe, &cache, None, &silent).unwrap();
    let asked = ranges.lock().unwrap().clone();
    assert_eq!(
        asked,
        ["none".to_string(), format!("{}-", archive.len() / 2)]
    );
    assert!(dataset.join("manifest.csv").is_file());
    assert!(!cache
        .join("downloads")
        .join(entry.file_name().unwrap())
        .exists());
    // A file that is not the recipe's: refused, removed, no entry.
    let other = scratch("download-other").join("cache");
    let (address, _) = serve(logs_zip("logs", &[("logs/extra.txt", "x")]), 0);
    let text =
        headerless_recipe(&archive, r#""10", "30""#).replace("https://example.org", &address);
    let recipe = Recipe::parse(&text, Path::new("r.toml")).unwrap();
    let err = fetch(&recipe, &other, None, &silent)
        .unwrap_err()
        .to_string();
    assert!(err.contains("SHA-256"), "{err}");
    let downloads = other
        .join("downloads")
        .join(datasets::fetch::entry(&other, &recipe).file_name().unwrap());
    assert!(listing(&downloads).is_empty(), "{:?}", listing(&downloads));
    // A missing file: the status, named with the URL.
    let text = headerless_recipe(&archive, r#""10", "30""#)
        .replace("https://example.org/data", &format!("{address}/gone"));
    let recipe = Recipe::parse(&text, Path::new("r.toml")).unwrap();
    let err = fetch(&recipe, &other, None, &silent)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("HTTP 404") && err.contains("/gone/logs.zip"),
        "{err}"
    );
}

/// Whether a file named `name` is anywhere under `dir`.
fn anywhere(dir: &Path, name: &str) -> bool {
    std::fs::read_dir(dir).is_ok_and(|items| {
        items.flatten().any(|item| {
            let path = item.path();
            item.file_name() == name || (path.is_dir() && anywhere(&path, name))
        })
    })
}

/// A tar.gz holding one regular file, `name` (written as raw bytes, so `..` is kept), or a
/// link when `link_to` is given.
fn hostile_tar(name: &str, link_to: Option<&str>) -> Vec<u8> {
    let gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    let mut tar = tar::Builder::new(gz);
    let mut header = tar::Header::new_gnu();
    header.as_gnu_mut().unwrap().name[..name.len()].copy_from_slice(name.as_bytes());
    header.set_mode(0o644);
    match link_to {
        Some(target) => {
            header.set_entry_type(tar::EntryType::Symlink);
            header.set_link_name(target).unwrap();
            header.set_size(0);
            header.set_cksum();
            tar.append(&header, std::io::empty()).unwrap();
        }
        None => {
            header.set_entry_type(tar::EntryType::Regular);
            header.set_size(4);
            header.set_cksum();
            tar.append(&header, &b"1,2\n"[..]).unwrap();
        }
    }
    tar.into_inner().unwrap().finish().unwrap()
}

#[test]
fn a_tar_entry_outside_its_folder_or_a_link_is_refused() {
    let dir = scratch("hostile-tar");
    let cache = dir.join("cache");
    std::fs::create_dir_all(dir.join("copy")).unwrap();
    let cases = [
        (
            hostile_tar("../escaped.csv", None),
            "escaped.csv",
            "outside",
        ),
        (
            hostile_tar("logs/link.csv", Some("/etc/passwd")),
            "link.csv",
            "link",
        ),
    ];
    for (bytes, name, why) in cases {
        std::fs::write(dir.join("copy/logs.tar.gz"), &bytes).unwrap();
        let text = headerless_recipe(&bytes, r#""10", "30""#)
            .replace("logs.zip", "logs.tar.gz")
            .replace("kind = \"zip\"", "kind = \"tar.gz\"");
        let recipe = Recipe::parse(&text, Path::new("r.toml")).unwrap();
        let err = fetch(&recipe, &cache, Some(&dir.join("copy")), &silent)
            .unwrap_err()
            .to_string();
        assert!(err.contains(name) && err.contains(why), "{err}");
        assert!(listing(&cache).is_empty(), "{:?}", listing(&cache));
        assert!(!anywhere(&dir, "escaped.csv") && !dir.join("escaped.csv").exists());
    }
}

#[test]
fn a_stacked_array_in_a_tar_gz_is_imported_with_its_speeds() {
    use ndarray::{Array1, Array4};
    let dir = scratch("stacked");
    let (n, rows, cols, t) = (24usize, 2usize, 2usize, 400usize);
    let mut rng = XorShift::new(3);
    let labels = Array1::from_shape_fn(n, |i| (i % 3) as i64);
    let speeds = Array1::from_shape_fn(n, |i| if i < n / 2 { 10.0 } else { 20.0 });
    let data = Array4::from_shape_fn((n, rows, cols, t), |(i, r, c, k)| {
        let f = 1.0 + (i % 3) as f64;
        (1.0 + (f * k as f64 / 50.0 + (r + c) as f64).sin()) * 100.0 + rng.fraction(100)
    });
    let files = dir.join("files");
    std::fs::create_dir_all(files.join("skin")).unwrap();
    ndarray_npy::write_npy(files.join("skin/data.npy"), &data).unwrap();
    ndarray_npy::write_npy(files.join("skin/labels.npy"), &labels).unwrap();
    ndarray_npy::write_npy(files.join("skin/speeds.npy"), &speeds).unwrap();
    let mut tar = tar::Builder::new(flate2::write::GzEncoder::new(
        Vec::new(),
        flate2::Compression::default(),
    ));
    tar.append_dir_all("skin", files.join("skin")).unwrap();
    let bytes = tar.into_inner().unwrap().finish().unwrap();
    std::fs::create_dir_all(dir.join("copy")).unwrap();
    std::fs::write(dir.join("copy/skin.tar.gz"), &bytes).unwrap();
    let text = format!(
        r#"
name = "skin"
title = "A fabricated stacked skin"
citation = "neurotex's tests"
licence = "CC-BY-4.0"
[[source]]
url = "https://example.org/skin.tar.gz"
kind = "tar.gz"
sha256 = "{}"
size = {}
[import]
kind = "stacked"
data = "skin/data.npy"
labels = "skin/labels.npy"
speeds = "skin/speeds.npy"
axes = "n,row,col,t"
fs = 1000
[conditions]
speed_mm_s = ["10", "20"]
[[protocol]]
id = "within-speed"
per = "speed_mm_s"
"#,
        sha256(&bytes),
        bytes.len()
    );
    let recipe = Recipe::parse(&text, Path::new("skin.toml")).unwrap();
    let dataset = fetch(
        &recipe,
        &dir.join("cache"),
        Some(&dir.join("copy/skin.tar.gz")),
        &silent,
    )
    .unwrap();
    let opened = neurotex::recording::Dataset::open(&dataset).unwrap();
    assert_eq!(opened.entries.len(), n);
    let at = |i: usize| {
        opened.entries[i]
            .field("speed_mm_s")
            .unwrap()
            .parse::<f64>()
            .unwrap()
    };
    assert_eq!((at(0), at(n - 1)), (10.0, 20.0));
}

/// `neurotex compare DATASET --per speed_mm_s --nested` over the benchmark's candidate set,
/// with `folds` and `seed` (one repeat): what a leaderboard's board must equal.
fn compare_nested_per_speed(dataset: &Path, folds: usize, seed: u64) -> Comparison {
    let (encodings, methods, classifiers) = neurotex::workflows::benchmark::candidate_set(false);
    let list = |s: String| s.split(',').map(String::from).collect::<Vec<_>>();
    let compare = CompareOptions {
        dataset: dataset.to_path_buf(),
        speeds: None,
        per: Some("speed_mm_s".into()),
        hold_out: None,
        train_where: None,
        test_where: None,
        group_by: None,
        encodings: list(encodings),
        methods: list(methods),
        classifiers: list(classifiers),
        tau_ms: neurotex::compare::candidates::STANDARD_TAU_MS,
        knn: KnnOptions::default(),
        snn: SnnOptions::default(),
        folds,
        repeats: 1,
        seed,
        nested: true,
        inner_folds: None,
        encoder_draws: 1,
        open: OpenOptions::default(),
    };
    let opened = compare.open.open(dataset).unwrap();
    compare
        .run(&opened, &StageOptions::default(), &silent)
        .unwrap()
}

/// `c` with every time set to 0 and without its provenance (when it ran, and the data's
/// folder): those differ from run to run, nothing else does.
fn without_times(mut c: Comparison) -> Comparison {
    for r in c.results.iter_mut() {
        r.seconds = 0.0;
    }
    c.best.seconds = 0.0;
    c.provenance.clear();
    c
}

/// The fabricated logs' archive in `dir/copy/` and their recipe `dir/ridges.toml` (two
/// speeds), whose path is returned.
fn ridges_in(dir: &Path) -> PathBuf {
    let archive = logs_zip("logs", &[]);
    std::fs::create_dir_all(dir.join("copy")).unwrap();
    std::fs::write(dir.join("copy/logs.zip"), &archive).unwrap();
    let recipe_path = dir.join("ridges.toml");
    std::fs::write(&recipe_path, headerless_recipe(&archive, r#""10", "30""#)).unwrap();
    recipe_path
}

/// `neurotex benchmark DIR/ridges.toml --from DIR/copy --cache DIR/cache --out DIR/OUT
/// --folds 3 --seed 5` over both protocols of [`ridges_in`]'s recipe.
fn ridges_bench(dir: &Path, out: &str) -> BenchmarkOptions {
    BenchmarkOptions {
        datasets: vec![dir.join("ridges.toml").display().to_string()],
        out: dir.join(out),
        cache: Some(dir.join("cache")),
        from: Some(dir.join("copy")),
        protocols: Vec::new(),
        snn: false,
        folds: 3,
        repeats: 1,
        seed: 5,
    }
}

#[test]
fn the_leaderboard_is_compare_nested_on_the_same_folds_and_a_rerun_keeps_it() {
    let dir = scratch("bench");
    let recipe_path = ridges_in(&dir);
    let options = ridges_bench(&dir, "out");
    let board = options.run(&silent).unwrap();
    assert_eq!(board.boards.len(), 2);
    let recipe = Recipe::read(&recipe_path).unwrap();
    let dataset = datasets::fetched(&dir.join("cache"), &recipe).unwrap();
    // `neurotex compare --per speed_mm_s --nested --encodings ... --folds 3 --repeats 1 --seed 5`.
    let direct = compare_nested_per_speed(&dataset, 3, 5);
    let from_board = board.boards[0].comparison.clone();
    assert_eq!(without_times(from_board), without_times(direct));
    let md = std::fs::read_to_string(dir.join("out/leaderboard.md")).unwrap();
    assert!(
        md.contains("Someone 2024") && md.contains("Nested selection"),
        "{md}"
    );
    // How nested selection ranked inside its training sets, and every rank accounted for:
    // the table ends at the last rank or says where the rest are.
    assert!(md.contains("Ranked by 3-fold cross-validation inside each outer training set."));
    // Two speeds: each outer training set of the held-out protocol holds one.
    assert!(md.contains("inside each outer training set (each holds one value of speed_mm_s)"));
    let n = board.boards[0].comparison.results.len();
    assert!(md.contains(&format!("–{n} in compare.md |")), "{md}");
    assert!(dir.join("out/ridges/within-speed/ranking.png").is_file());
    assert!(dir.join("out/leaderboard.png").is_file() && dir.join("out/leaderboard.svg").is_file());
    // A nested interval under chance, or across it, is said so.
    let mut low = board.clone();
    let c = &mut low.boards[0].comparison;
    let chance = c.chance;
    c.nested.as_mut().unwrap().ci = [chance / 3.0, chance / 2.0];
    let md = neurotex::workflows::benchmark::markdown(&low);
    assert!(md.contains("**Below chance**"), "{md}");
    let c = &mut low.boards[0].comparison;
    c.nested.as_mut().unwrap().ci = [chance / 2.0, 2.0 * chance];
    let md = neurotex::workflows::benchmark::markdown(&low);
    assert!(
        md.contains("**Not above chance**") && !md.contains("Below chance"),
        "{md}"
    );
    // Within each speed the ridges are told apart well above chance: no such line.
    let mut within = board.clone();
    within.boards.truncate(1);
    let md = neurotex::workflows::benchmark::markdown(&within);
    assert!(
        !md.contains("Below chance") && !md.contains("above chance"),
        "{md}"
    );
    // A rerun keeps both comparisons: same leaderboard, times included; another seed is
    // compared anew.
    let said = std::sync::Mutex::new(Vec::<String>::new());
    let on = |p: neurotex::progress::Progress| {
        if let neurotex::progress::Progress::Say(s) = p {
            said.lock().unwrap().push(s.to_string());
        }
    };
    let kept = |said: &std::sync::Mutex<Vec<String>>| {
        let said = said.lock().unwrap();
        said.iter()
            .filter(|s| s.contains("kept from an earlier run"))
            .count()
    };
    let again = BenchmarkOptions {
        from: None,
        ..options.clone()
    }
    .run(&on)
    .unwrap();
    assert_eq!(again, board);
    assert_eq!(kept(&said), 2);
    BenchmarkOptions {
        from: None,
        seed: 6,
        ..options
    }
    .run(&on)
    .unwrap();
    assert_eq!(kept(&said), 2);
}

/// A progress callback that stops the run (by a panic, as a signal would) at the step after
/// `n` steps of the comparison's first stage, its candidates' scores.
fn stop_after(n: usize) -> impl Fn(neurotex::progress::Progress) + Sync {
    use neurotex::progress::Progress;
    use std::sync::atomic::{AtomicUsize, Ordering};
    // usize::MAX until the candidates' stage begins.
    let ticks = AtomicUsize::new(usize::MAX);
    move |p| match p {
        Progress::Stage("candidates", _) => ticks.store(0, Ordering::SeqCst),
        Progress::Tick
            if ticks.load(Ordering::SeqCst) != usize::MAX
                && ticks.fetch_add(1, Ordering::SeqCst) == n =>
        {
            panic!("stopped part way")
        }
        _ => {}
    }
}

#[test]
fn a_benchmark_stopped_part_way_resumes_from_its_finished_pieces() {
    let dir = scratch("resume");
    ridges_in(&dir);
    let options = |out: &str, seed: u64| BenchmarkOptions {
        protocols: vec!["within-speed".into()],
        seed,
        ..ridges_bench(&dir, out)
    };
    let whole = options("whole", 5).run(&silent).unwrap();
    // Stopped after 30 candidates' finished scores, as an interrupted run would be.
    let stopped = std::panic::catch_unwind(|| options("resumed", 5).run(&stop_after(30)));
    assert!(stopped.is_err());
    let pieces = dir.join("resumed/ridges/within-speed.pieces");
    let kept = listing(&pieces)
        .iter()
        .filter(|f| f.ends_with(".piece"))
        .count();
    assert!(kept >= 30, "{:?}", listing(&pieces));
    assert!(!dir.join("resumed/ridges/within-speed.key.json").exists());
    // Run again: the pieces are taken, the rest computed, the same leaderboard results.
    let said = std::sync::Mutex::new(Vec::<String>::new());
    let on = |p: neurotex::progress::Progress| {
        if let neurotex::progress::Progress::Say(s) = p {
            said.lock().unwrap().push(s.to_string());
        }
    };
    let resumed = options("resumed", 5).run(&on).unwrap();
    let taken: Vec<String> = said
        .lock()
        .unwrap()
        .iter()
        .filter(|s| s.contains("finished pieces taken"))
        .cloned()
        .collect();
    assert_eq!(
        taken,
        [format!(
            "  {kept} finished pieces taken (kept by a run stopped part way, or by shares)"
        )]
    );
    // Said before the comparison runs too, with the pieces the folder held.
    let found = format!("  {kept} finished pieces found, kept by a run stopped part way (or by shares): taken up, not computed again");
    assert!(said.lock().unwrap().contains(&found), "{found}");
    let comparison = |b: &neurotex::workflows::benchmark::Leaderboard| {
        without_times(b.boards[0].comparison.clone())
    };
    assert_eq!(comparison(&resumed), comparison(&whole));
    assert!(!pieces.exists() && dir.join("resumed/ridges/within-speed.key.json").exists());
    // Pieces of other settings are never taken: stopped under seed 5, run under seed 6.
    assert!(std::panic::catch_unwind(|| options("other", 5).run(&stop_after(30))).is_err());
    said.lock().unwrap().clear();
    let other = options("other", 6).run(&on).unwrap();
    assert!(said
        .lock()
        .unwrap()
        .iter()
        .all(|s| !s.contains("pieces taken")));
    // ... and their removal is said, with the setting that differed.
    let removed = said.lock().unwrap().iter().find_map(|s| {
        let n = s.strip_suffix(
            " finished pieces of a stopped run with other settings (seed: 5 → 6) removed",
        )?;
        n.trim().parse::<usize>().ok()
    });
    assert!(removed.is_some_and(|n| n >= 30), "{said:?}");
    // A folder of the user's where the pieces would go is never removed.
    let theirs = dir.join("mine/ridges/within-speed.pieces");
    std::fs::create_dir_all(&theirs).unwrap();
    std::fs::write(theirs.join("notes.txt"), "mine").unwrap();
    let err = options("mine", 5).run(&silent).unwrap_err().to_string();
    assert!(
        err.contains("notes.txt") && err.contains("another --out"),
        "{err}"
    );
    assert!(theirs.join("notes.txt").is_file());
    assert_eq!(
        comparison(&other),
        comparison(&options("seed6", 6).run(&silent).unwrap())
    );
}

#[test]
fn shares_computed_apart_make_the_leaderboard_of_one_run() {
    let dir = scratch("shares");
    ridges_in(&dir);
    let options = |out: &str| ridges_bench(&dir, out);
    let whole = options("whole").run(&silent).unwrap();
    let apart = options("apart");
    let shares = apart.shares(&silent).unwrap();
    // Both protocols, each split by the set's two spike encodings and their eight feature
    // methods, and the baselines without spikes in one share.
    assert_eq!(shares.len(), 2 * (2 * 8 + 1), "{shares:?}");
    let baselines = shares.iter().filter(|s| s.encoding == "none");
    assert!(baselines.clone().all(|s| s.method.is_none()));
    assert_eq!(baselines.count(), 2);
    // A share whose folder was not made for these settings is refused.
    let other = BenchmarkOptions {
        seed: 6,
        ..apart.clone()
    };
    let err = other
        .run_share(&shares[0], &silent)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("not the pieces folder of these settings"),
        "{err}"
    );
    // The shares in reverse order, as a cluster may finish them.
    for share in shares.iter().rev() {
        apart.run_share(share, &silent).unwrap();
    }
    // The final run takes every piece its stages count (each candidate's score on each
    // part, each candidate inside each outer split) and computes none.
    let said = std::sync::Mutex::new(Vec::<String>::new());
    let on = |p: neurotex::progress::Progress| match p {
        neurotex::progress::Progress::Say(s) => said.lock().unwrap().push(s.to_string()),
        neurotex::progress::Progress::Stage(name, n) => {
            said.lock().unwrap().push(format!("stage {name} {n}"))
        }
        neurotex::progress::Progress::Advice(s) => {
            said.lock().unwrap().push(format!("warning {s}"))
        }
        _ => {}
    };
    let board = apart.run(&on).unwrap();
    let said = said.into_inner().unwrap();
    // A warning names the comparison it is about: the held-out protocol's inner ranking,
    // with one speed left in each outer training set, cross-validates within it.
    let warned: Vec<&String> = said.iter().filter(|s| s.starts_with("warning ")).collect();
    assert!(
        warned
            .iter()
            .any(|s| s.starts_with("warning ridges, speed-held-out: ")),
        "{warned:?}"
    );
    assert!(
        warned.iter().all(|s| s.starts_with("warning ridges, ")),
        "{warned:?}"
    );
    let mut needed = 0;
    let mut taken = Vec::new();
    for line in &said {
        if let Some(n) = line
            .strip_prefix("stage candidates ")
            .or(line.strip_prefix("stage nested selection "))
        {
            needed += n.parse::<usize>().unwrap();
        } else if line.contains("finished pieces taken") {
            let n = line.split_whitespace().next().unwrap().parse::<usize>();
            taken.push((std::mem::take(&mut needed), n.unwrap()));
        }
    }
    assert_eq!(taken.len(), 2, "{said:?}");
    assert!(taken.iter().all(|(needed, n)| needed == n), "{taken:?}");
    for (a, b) in board.boards.iter().zip(&whole.boards) {
        assert_eq!(
            without_times(a.comparison.clone()),
            without_times(b.comparison.clone())
        );
    }
    // Nothing is left to share once both protocols are kept.
    assert!(apart.shares(&silent).unwrap().is_empty());
}

#[test]
#[ignore = "FabricSlide from ../shared: about 40 s"]
fn fabricslide_leaderboard_is_compare_nested_with_wangs_number_beside() {
    let copy =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/fabricslide/fabric");
    let dir = scratch("fabricslide");
    let options = BenchmarkOptions {
        datasets: vec!["fabricslide".into()],
        out: dir.join("out"),
        cache: Some(dir.join("cache")),
        from: Some(copy),
        protocols: vec!["within-velocity".into()],
        snn: false,
        folds: 5,
        repeats: 1,
        seed: 0,
    };
    let board = options.run(&silent).unwrap();
    assert_eq!(board.boards.len(), 1);
    let b = &board.boards[0];
    assert_eq!(
        (b.published[0].accuracy, b.published[0].citation.as_str()),
        (0.96, "Wang et al. 2022")
    );
    let dataset = datasets::fetched(
        &dir.join("cache"),
        &datasets::resolve("fabricslide").unwrap(),
    )
    .unwrap();
    let direct = compare_nested_per_speed(&dataset, 5, 0);
    assert_eq!(
        without_times(b.comparison.clone()),
        without_times(direct.clone())
    );
    assert!(direct.nested.unwrap().accuracy > direct.chance + 0.5);
}
