//! NIR graphs written by snnTorch's and Norse's own exporters (`tests/data/foreign_nir`,
//! made by `tools/nir_interop/foreign_graphs.py`; its README names the versions) run in
//! `predict --like --nir-from TOOL` and `stream` with the tool's own decisions and scores.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::stream::{csv_text, lines, of_file, slide_frames, slides};
use crate::util::{s, Dir};

/// The graphs, the tool named after `--nir-from`.
const GRAPHS: [(&str, &str); 4] = [
    ("snntorch-synaptic", "snntorch"),
    ("snntorch-leaky", "snntorch"),
    ("snntorch-rleaky", "snntorch"),
    ("norse-lifbox", "norse"),
];

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/foreign_nir")
}

/// The dataset the tools ran on: `neurotex simulate` with the README's seed and options.
fn simulated(dir: &Dir) -> PathBuf {
    let data = dir.join("sim");
    dir.ok(&[
        "simulate",
        "--out",
        s(&data),
        "--seed",
        "3",
        "--trials",
        "3",
        "--speeds",
        "15",
        "--textures",
        "FT1,RT,CP,SB",
    ]);
    data
}

/// A CSV file's rows as maps from column to value.
fn rows(path: &Path) -> Vec<HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut it = text.lines();
    let header: Vec<&str> = it.next().unwrap().split(',').collect();
    it.map(|l| {
        (header.iter().map(|h| h.to_string()))
            .zip(l.split(',').map(str::to_string))
            .collect()
    })
    .collect()
}

/// The tool's decision and softmax shares per recording, from its scores.
fn tool_shares(graph: &str) -> HashMap<String, (String, Vec<(String, f64)>)> {
    let path = fixtures().join(format!("{graph}.scores.csv"));
    rows(&path)
        .into_iter()
        .map(|r| {
            let mut scores: Vec<(String, f64)> = (r.iter())
                .filter_map(|(k, v)| Some((k.strip_prefix("score_")?.to_string(), v.parse().ok()?)))
                .collect();
            scores.sort_by(|a, b| a.0.cmp(&b.0));
            let top = scores.iter().map(|x| x.1).fold(f64::MIN, f64::max);
            let sum: f64 = scores.iter().map(|x| (x.1 - top).exp()).sum();
            let shares = (scores.iter())
                .map(|(c, v)| (c.clone(), (v - top).exp() / sum))
                .collect();
            (r["file"].clone(), (r["predicted"].clone(), shares))
        })
        .collect()
}

#[test]
fn graphs_from_snntorch_and_norse_predict_the_tools_decisions() {
    let dir = Dir::new();
    let data = simulated(&dir);
    let like = fixtures().join("like.json");
    for (graph, tool) in GRAPHS {
        let model = fixtures().join(format!("{graph}.nir"));
        let out = dir.join(&format!("{graph}.csv"));
        dir.ok(&[
            "predict",
            "--model",
            s(&model),
            "--like",
            s(&like),
            "--nir-from",
            tool,
            "--dataset",
            s(&data),
            "--out",
            s(&out),
        ]);
        let want = tool_shares(graph);
        let got = rows(&out);
        assert_eq!(got.len(), want.len(), "{graph}");
        for row in got {
            let (decision, shares) = &want[&row["file"]];
            assert_eq!(&row["predicted"], decision, "{graph} {}", row["file"]);
            for (class, share) in shares {
                let ours: f64 = row[&format!("share_{class}")].parse().unwrap();
                // float32 in the tool, float64 here
                assert!(
                    (ours - share).abs() < 1e-5,
                    "{graph} {class}: {ours} vs {share}"
                );
            }
        }
    }
    // The decisions are not all one class, so that agreeing says something.
    let decided: std::collections::HashSet<String> = (tool_shares("snntorch-synaptic")
        .into_values())
    .map(|d| d.0)
    .collect();
    assert!(decided.len() >= 3, "{decided:?}");
}

#[test]
fn graphs_read_without_their_tools_convention_are_refused_by_name() {
    let dir = Dir::new();
    let data = simulated(&dir);
    let like = fixtures().join("like.json");
    let never = dir.join("never.csv");
    let run = |graph: &str, extra: &[&str]| {
        let model = fixtures().join(format!("{graph}.nir"));
        let mut args = vec![
            "predict",
            "--model",
            s(&model),
            "--dataset",
            s(&data),
            "--out",
            s(&never),
        ];
        args.extend_from_slice(extra);
        dir.fails(&args)
    };
    let cases: [(&str, Vec<&str>, &str); 6] = [
        // Norse's time constants are written multiplied by dt: read as seconds, 0.4 ms.
        (
            "norse-lifbox",
            vec!["--like", s(&like)],
            "node 1: `tau` 0.0003999",
        ),
        // snnTorch's constants are for its 0.1 ms step: read as NIR's seconds at 10 ms.
        (
            "snntorch-leaky",
            vec!["--like", s(&like)],
            "node 1: `tau` 0.0003999",
        ),
        // Read as Norse's (the same decays at a 10 ms step), its readout Leaky fires.
        (
            "snntorch-leaky",
            vec!["--like", s(&like), "--nir-from", "norse"],
            "node 3: a LIF readout that fires",
        ),
        // Neither tool writes a time step.
        ("snntorch-leaky", vec!["--nir-from", "snntorch"], "--like"),
        ("norse-lifbox", vec!["--nir-from", "norse"], "--like"),
        (
            "norse-lifbox",
            vec!["--like", s(&like), "--nir-from", "keras"],
            "nir, snntorch or norse",
        ),
    ];
    for (graph, extra, want) in cases {
        let err = run(graph, &extra);
        assert!(err.contains(want), "{graph} {extra:?}: {err}");
    }
    assert!(!never.exists());
    // A pipeline with another number of taxels than the graph's inputs.
    let other = dir.join("other.json");
    let mut file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&like).unwrap()).unwrap();
    file["pipeline"]["encoding"] = serde_json::Value::from("sa+fa");
    file["network"]["inputs"] = serde_json::Value::from(32);
    file["network"]["w_in"] = serde_json::Value::from(vec![0.0; 32 * 2]);
    std::fs::write(&other, file.to_string()).unwrap();
    let err = run(
        "norse-lifbox",
        &["--like", s(&other), "--nir-from", "norse"],
    );
    assert!(err.contains("16 inputs") && err.contains("= 32"), "{err}");
}

#[test]
fn graphs_from_snntorch_and_norse_stream_as_they_predict() {
    let dir = Dir::new();
    let data = simulated(&dir);
    let like = fixtures().join("like.json");
    let row = &slides(&data)[7];
    let csv = dir.join("slide.csv");
    std::fs::write(&csv, csv_text(&slide_frames(&data, row))).unwrap();
    for (graph, tool) in [GRAPHS[0], GRAPHS[2], GRAPHS[3]] {
        let model = fixtures().join(format!("{graph}.nir"));
        let graph_args = ["--model", s(&model), "--like", s(&like), "--nir-from", tool];
        let out = dir.join("causal.jsonl");
        let mut predict = vec![
            "predict",
            "--dataset",
            s(&data),
            "--causal",
            "--out",
            s(&out),
        ];
        predict.extend_from_slice(&graph_args);
        dir.ok(&predict);
        let expected = of_file(&lines(&std::fs::read_to_string(&out).unwrap()), &row.0);
        let mut stream = vec!["stream", "--input", s(&csv)];
        stream.extend_from_slice(&graph_args);
        let streamed = lines(&dir.ok(&stream));
        assert_eq!(streamed, expected, "{graph}");
        let last = streamed.last().unwrap();
        assert_eq!(last["end"], true);
        let (decision, _) = &tool_shares(graph)[&row.0];
        assert_eq!(last["label"], decision.as_str(), "{graph}: {last}");
    }
}
