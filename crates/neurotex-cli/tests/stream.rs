//! `neurotex stream` and `neurotex predict --causal`: the same lines for the same recording
//! (from a file, standard input, TCP and UDP; CSV and raw f32 frames), bad frames counted
//! and skipped, offline models refused; on FabricSlide too.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpStream, UdpSocket};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use ndarray::Array3;
use ndarray_npy::read_npy;
use serde_json::Value;

use crate::util::{fabricslide, s, Dir};

/// A simulated dataset of FT1, SB and CP x 4 trials at 10 mm/s (hold 5 s, slide 9 s), and a
/// causal model trained on it with `extra` options.
pub(crate) fn trained(dir: &Dir, extra: &[&str]) -> (PathBuf, PathBuf) {
    let data = dir.join("sim");
    dir.ok(&[
        "simulate",
        "--out",
        s(&data),
        "--trials",
        "4",
        "--speeds",
        "10",
        "--textures",
        "FT1,SB,CP",
    ]);
    let model = dir.join("model.json");
    let mut args = vec![
        "train",
        "--dataset",
        s(&data),
        "--causal",
        "--out",
        s(&model),
    ];
    args.extend_from_slice(extra);
    dir.ok(&args);
    (data, model)
}

/// The manifest's rows as `(file, slide_start_s, slide_end_s)`.
pub(crate) fn slides(data: &Path) -> Vec<(String, f64, f64)> {
    let text = std::fs::read_to_string(data.join("manifest.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (start, end) = (col("slide_start_s"), col("slide_end_s"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[0].to_string(),
                f[start].parse().unwrap(),
                f[end].parse().unwrap(),
            )
        })
        .collect()
}

/// The sliding phase of a simulated recording: `(frames, 16 values)` at 1 kHz, selected as
/// the pipeline selects it (step `i` at `i / 1000` s, in `[start, end)`).
pub(crate) fn slide_frames(data: &Path, (file, start, end): &(String, f64, f64)) -> Vec<Vec<f32>> {
    let x: Array3<f32> = read_npy(data.join(file)).unwrap();
    (0..x.shape()[0])
        .filter(|&i| {
            let t = i as f64 / 1000.0;
            t >= start - 1e-9 && t < end - 1e-9
        })
        .map(|i| x.slice(ndarray::s![i, .., ..]).iter().copied().collect())
        .collect()
}

/// Frames as CSV text: a header of taxel names, then one line per frame.
pub(crate) fn csv_text(frames: &[Vec<f32>]) -> String {
    let mut text: String = (0..16)
        .map(|i| format!("taxel{i}"))
        .collect::<Vec<_>>()
        .join(",");
    text.push('\n');
    for f in frames {
        let line: Vec<String> = f.iter().map(|v| v.to_string()).collect();
        text.push_str(&line.join(","));
        text.push('\n');
    }
    text
}

/// JSON lines, parsed.
pub(crate) fn lines(text: &str) -> Vec<Value> {
    text.lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect()
}

/// What `predict --causal` writes for `file` of `data`: the lines a stream of its frames
/// prints.
pub(crate) fn predicted(dir: &Dir, model: &Path, data: &Path, file: &str) -> Vec<Value> {
    of_file(&causal_lines(dir, model, data), file)
}

/// Every line `predict --causal` writes for `data`, each checked to carry its recording's
/// label from the manifest as `true_label` beside the class chosen.
fn causal_lines(dir: &Dir, model: &Path, data: &Path) -> Vec<Value> {
    let out = dir.join("causal.jsonl");
    let args = ["predict", "--model", s(model), "--dataset", s(data)];
    dir.ok(&[&args[..], &["--causal", "--out", s(&out)]].concat());
    let all = lines(&std::fs::read_to_string(out).unwrap());
    let manifest = std::fs::read_to_string(data.join("manifest.csv")).unwrap();
    let rows: Vec<Vec<&str>> = manifest.lines().map(|r| r.split(',').collect()).collect();
    let label = rows[0].iter().position(|h| *h == "label").unwrap();
    for l in &all {
        let row = rows.iter().find(|r| r[0] == l["file"].as_str().unwrap());
        assert_eq!(l["true_label"], row.unwrap()[label], "{l}");
    }
    all
}

/// `file`'s lines of `predict --causal` without `file` and `true_label`, which a stream
/// does not know.
pub(crate) fn of_file(all: &[Value], file: &str) -> Vec<Value> {
    let mut mine: Vec<Value> = all.iter().filter(|l| l["file"] == file).cloned().collect();
    for l in &mut mine {
        let line = l.as_object_mut().unwrap();
        line.remove("file");
        line.remove("true_label");
    }
    mine
}

/// A stream's lines without the end's count of bad frames (to compare a stream that had
/// bad frames with a clean one).
fn streamed(text: &str) -> Vec<Value> {
    let mut all = lines(text);
    for l in &mut all {
        l.as_object_mut().unwrap().remove("bad_frames");
    }
    all
}

/// `neurotex stream ARGS` with `input` on standard input; its standard output and error.
fn stream_stdin(dir: &Dir, args: &[&str], input: &[u8]) -> (String, String) {
    let mut child = spawn(dir, args);
    let mut stdin = child.stdin.take().unwrap();
    // Written from a thread: a child that warns a lot fills its standard error while the
    // input is still being written, and would wait on us as we wait on it.
    let input = input.to_vec();
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let out = finish(child);
    writer.join().unwrap().unwrap();
    out
}

fn spawn(dir: &Dir, args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_neurotex"))
        .arg("stream")
        .args(args)
        .current_dir(dir.path())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs")
}

fn finish(child: Child) -> (String, String) {
    let out = child.wait_with_output().unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert!(out.status.success(), "stream failed: {stderr}");
    (stdout, stderr)
}

/// The address a stream says it listens or receives on, read from its standard error.
fn announced(child: &mut Child) -> String {
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    err.read_line(&mut line).unwrap();
    let address = line.trim().rsplit("://").next().unwrap().to_string();
    // Keep reading standard error in the background so the child never blocks on it.
    std::thread::spawn(move || {
        let mut rest = String::new();
        err.read_to_string(&mut rest).ok();
    });
    address
}

#[test]
fn stream_and_predict_causal_agree_on_simulated_recordings() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &[]);
    let all = slides(&data);
    for row in [&all[1], &all[6]] {
        let expected = predicted(&dir, &model, &data, &row.0);
        assert!(expected.len() > 40, "a bin every 200 ms of a 9 s slide");
        assert_eq!(expected.last().unwrap()["end"], true);
        let frames = slide_frames(&data, row);
        // From a file.
        let csv = dir.join("slide.csv");
        std::fs::write(&csv, csv_text(&frames)).unwrap();
        let text = dir.ok(&["stream", "--model", s(&model), "--input", s(&csv)]);
        assert_eq!(lines(&text), expected, "{}", row.0);
        // Raw f32 frames on standard input.
        let raw: Vec<u8> = frames
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let (text, _) = stream_stdin(&dir, &["--model", s(&model), "--format", "f32le"], &raw);
        assert_eq!(lines(&text), expected, "f32le {}", row.0);
    }
}

#[test]
fn a_spiking_network_streams_as_predict_causal_decides_and_exports_to_nir() {
    // `train --classifier snn --causal`: the network runs on the stream's spikes step by
    // step; `predict --causal` runs it over the whole recording; the same lines. The same
    // network read back from its NIR graph streams the same lines too. Feed-forward and
    // recurrent.
    for recurrent in [false, true] {
        let dir = Dir::new();
        let mut args = vec![
            "--classifier",
            "snn",
            "--snn-epochs",
            "5",
            "--snn-hidden",
            "32",
        ];
        if recurrent {
            args.push("--snn-recurrent");
        }
        let (data, model) = trained(&dir, &args);
        let file: Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
        let weights = file["network"]["w_rec"].as_array().map_or(0, Vec::len);
        assert_eq!(weights, if recurrent { 32 * 32 } else { 0 });
        let graph = dir.join("model.nir");
        dir.ok(&["export", "nir", "--model", s(&model), "--out", s(&graph)]);
        let row = &slides(&data)[4];
        let expected = predicted(&dir, &model, &data, &row.0);
        assert!(expected.len() > 40, "a bin every 200 ms of a 9 s slide");
        assert_eq!(expected.last().unwrap()["end"], true);
        let csv = dir.join("slide.csv");
        std::fs::write(&csv, csv_text(&slide_frames(&data, row))).unwrap();
        for m in [&model, &graph] {
            let text = dir.ok(&["stream", "--model", s(m), "--input", s(&csv)]);
            assert_eq!(lines(&text), expected, "{}", m.display());
        }
        if recurrent {
            // A time-stamp column read as a taxel (the header names it so) is refused
            // rather than streamed as one more taxel.
            let frames = slide_frames(&data, row);
            let stamped: String = std::iter::once(format!(
                "timestamp,{}",
                (0..15)
                    .map(|i| format!("c{i}"))
                    .collect::<Vec<_>>()
                    .join(",")
            ))
            .chain(frames.iter().enumerate().map(|(k, f)| {
                let values: Vec<String> = f[..15].iter().map(|v| v.to_string()).collect();
                format!("{k},{}", values.join(","))
            }))
            .collect::<Vec<_>>()
            .join("\n");
            let bad = dir.join("stamped.csv");
            std::fs::write(&bad, stamped).unwrap();
            let err = dir.fails(&["stream", "--model", s(&model), "--input", s(&bad)]);
            assert!(
                err.contains("column `timestamp` is named like time stamps"),
                "{err}"
            );
        }
        // A window of 1 s: the scores read over the network's last 100 time steps.
        let one = [
            "stream",
            "--model",
            s(&model),
            "--input",
            s(&csv),
            "--window-s",
            "1",
        ];
        assert_ne!(lines(&dir.ok(&one)), expected);
    }
}

#[test]
fn tcp_and_udp_streams_end_with_the_summary() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &["--method", "all-taxels"]);
    let row = &slides(&data)[3];
    let expected = predicted(&dir, &model, &data, &row.0);
    let frames = slide_frames(&data, row);
    let text = csv_text(&frames);

    let mut child = spawn(
        &dir,
        &["--model", s(&model), "--input", "tcp://127.0.0.1:0"],
    );
    let address = announced(&mut child);
    let mut socket = TcpStream::connect(&address).unwrap();
    socket.write_all(text.as_bytes()).unwrap();
    drop(socket); // a closed connection ends the input
    let (out, _) = finish(child);
    assert_eq!(lines(&out), expected, "tcp");

    let mut child = spawn(
        &dir,
        &["--model", s(&model), "--input", "udp://127.0.0.1:0"],
    );
    let address = announced(&mut child);
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    // Whole lines per datagram, 20 frames at a time, then an empty datagram.
    let all: Vec<&str> = text.lines().collect();
    for chunk in all.chunks(20) {
        let datagram = chunk.join("\n") + "\n";
        socket.send_to(datagram.as_bytes(), &address).unwrap();
        // Loopback drops datagrams only when the receiver's buffer overflows: pace them.
        std::thread::sleep(std::time::Duration::from_micros(300));
    }
    socket.send_to(&[], &address).unwrap();
    let (out, _) = finish(child);
    assert_eq!(lines(&out), expected, "udp");
}

#[test]
fn bad_frames_are_warned_about_counted_and_skipped() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &[]);
    let row = &slides(&data)[0];
    let frames = slide_frames(&data, row);
    // Stamped in ms, so that a repeated stamp is a bad frame too.
    let names: Vec<String> = (0..16).map(|i| format!("c{i}")).collect();
    let mut clean = format!("t_ms,{}\n", names.join(","));
    let mut hostile = clean.clone();
    for (i, f) in frames.iter().enumerate() {
        let values: Vec<String> = f.iter().map(|v| v.to_string()).collect();
        let line = format!("{i},{}\n", values.join(","));
        clean.push_str(&line);
        hostile.push_str(&line);
        if i % 1000 == 500 {
            hostile.push_str(&line); // the same stamp again
            hostile.push_str(&format!("{}.5,{}\n", i, values[..15].join(","))); // 15 values
            hostile.push_str(&format!("{}.5,NaN,{}\n", i, values[1..].join(",")));
            hostile.push_str(&format!("{}.5,x,{}\n", i, values[1..].join(",")));
            hostile.push_str(&format!("NaN,{}\n", values.join(",")));
        }
    }
    let args = ["--model", s(&model)];
    let (good, _) = stream_stdin(&dir, &args, clean.as_bytes());
    let (out, err) = stream_stdin(&dir, &args, hostile.as_bytes());
    let bad = 5 * frames
        .iter()
        .enumerate()
        .filter(|(i, _)| i % 1000 == 500)
        .count();
    assert_eq!(streamed(&out), streamed(&good));
    let end = lines(&out).pop().unwrap();
    assert_eq!(end["bad_frames"], bad, "{err}");
    assert_eq!(err.matches("bad frame skipped").count(), bad, "{err}");
    assert!(err.contains("is not after the previous frame's"), "{err}");
    assert!(err.contains("16 fields, expected 17"), "{err}");
    assert!(err.contains("value 1 is NaN, not a finite number"), "{err}");
    assert!(
        err.contains("the time stamp NaN is not a finite number"),
        "{err}"
    );
    assert!(err.contains("value 1 is \"x\", not a number"), "{err}");
}

#[test]
fn reset_lines_and_frames_end_episodes() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &[]);
    let frames = slide_frames(&data, &slides(&data)[2]);
    let text = csv_text(&frames);
    let twice = format!("{text}reset\n{}", text.split_once('\n').unwrap().1);
    let (out, _) = stream_stdin(&dir, &["--model", s(&model)], twice.as_bytes());
    let ends: Vec<Value> = lines(&out)
        .into_iter()
        .filter(|l| l["end"] == true)
        .collect();
    assert_eq!(ends.len(), 2);
    assert_eq!(ends[0]["ended_by"], "reset");
    assert_eq!(ends[1]["ended_by"], "end_of_input");
    assert_eq!(ends[0]["label"], ends[1]["label"]);
    // The f32le reset frame: every value NaN.
    let mut raw: Vec<u8> = frames
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    raw.extend(std::iter::repeat_n(f32::NAN.to_le_bytes(), 16).flatten());
    raw.extend(frames.iter().flatten().flat_map(|v| v.to_le_bytes()));
    let (out, _) = stream_stdin(&dir, &["--model", s(&model), "--format", "f32le"], &raw);
    assert_eq!(lines(&out).iter().filter(|l| l["end"] == true).count(), 2);
}

/// Sends SIGINT to a child process.
fn interrupt(child: &Child) {
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success());
}

#[test]
fn an_interrupt_ends_the_stream_with_its_summary() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &[]);
    let frames = slide_frames(&data, &slides(&data)[0]);
    let text = csv_text(&frames);
    let (head, rest) = text.split_at(text.len() / 2);
    let next_line = rest.split_inclusive('\n').nth(1).unwrap();

    // A frame arrives after the interrupt: the stream ends there, with the summary.
    let mut child = spawn(&dir, &["--model", s(&model)]);
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(head.as_bytes()).unwrap();
    stdin.flush().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(500));
    interrupt(&child);
    std::thread::sleep(std::time::Duration::from_millis(300));
    stdin.write_all(next_line.as_bytes()).unwrap();
    stdin.flush().unwrap();
    let (out, err) = finish(child);
    let all = lines(&out);
    let end = all.last().unwrap();
    assert_eq!(end["end"], true, "{out}");
    assert_eq!(end["ended_by"], "stopped");
    assert!(all.len() > 2, "bins before the end: {out}");
    assert!(err.contains("interrupted"), "{err}");
    drop(stdin);

    // No frame after the interrupt: the run ends within the grace time, exit 130.
    let mut child = spawn(&dir, &["--model", s(&model)]);
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(head.as_bytes()).unwrap();
    stdin.flush().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(500));
    let start = std::time::Instant::now();
    interrupt(&child);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130));
    assert!(start.elapsed().as_secs_f64() < 10.0);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("without its summary"), "{err}");
    drop(stdin);
}

#[test]
fn offline_models_and_bad_options_are_refused() {
    let dir = Dir::new();
    let (data, _) = trained(&dir, &[]);
    let offline = dir.join("offline.json");
    dir.ok(&["train", "--dataset", s(&data), "--out", s(&offline)]);
    let err = dir.fails(&["stream", "--model", s(&offline), "--input", "x.csv"]);
    assert!(err.contains("--causal"), "{err}");
    let err = dir.fails(&[
        "predict",
        "--model",
        s(&offline),
        "--dataset",
        s(&data),
        "--causal",
        "--out",
        "o.jsonl",
    ]);
    assert!(err.contains("--causal"), "{err}");
    assert!(!dir.join("o.jsonl").exists());
    let model = dir.join("model.json");
    for (args, says) in [
        (vec!["--decide", "1.5"], "decision share"),
        (vec!["--decide-bins", "0"], "consecutive bins"),
        (vec!["--window-s", "-1"], "`window-s`"),
        (vec!["--episode", "onset:x"], "episodes are"),
        (vec!["--fs", "0"], "frame rate"),
        (vec!["--max-gap-s", "3600"], "largest gap"),
        (vec!["--input", "missing.csv"], "missing.csv"),
        (vec!["--input", "tcp://not-an-address"], "tcp://"),
    ] {
        let mut all = vec!["stream", "--model", s(&model)];
        all.extend(args);
        let err = dir.fails(&all);
        assert!(err.contains(says), "{all:?}: {err}");
    }
}

#[test]
#[ignore = "needs ../shared/data/fabricslide beside the repository; .ci/run runs it"]
fn fabricslide_stream_equals_predict_causal() {
    let dir = Dir::new();
    let data = dir.join("fabricslide");
    dir.ok(&[
        "import",
        "csv",
        s(&fabricslide()),
        "--out",
        s(&data),
        "--name-pattern",
        "{label}_F{force}_V{speed}mmps_{trial}.csv",
        "--time-column",
        "timestamp",
        "--channels",
        r"^channel\d+$",
        "--grid",
        "4x4",
        "--baseline",
        "min",
    ]);
    let model = dir.join("model.json");
    dir.ok(&[
        "train",
        "--dataset",
        s(&data),
        "--speeds",
        "20",
        "--causal",
        "--encoding",
        "sa+fa",
        "--method",
        "all-taxels",
        "--classifier",
        "forest",
        "--out",
        s(&model),
    ]);
    // The imported logs (t_ms and 16 channels at about 35.7 Hz), streamed as they are.
    let manifest = std::fs::read_to_string(data.join("manifest.csv")).unwrap();
    let files: Vec<&str> = manifest
        .lines()
        .skip(1)
        .filter(|l| l.contains(",20,"))
        .map(|l| l.split(',').next().unwrap())
        .step_by(9)
        .collect();
    assert!(files.len() >= 3);
    let all = causal_lines(&dir, &model, &data);
    for file in files {
        let expected = of_file(&all, file);
        let text = dir.ok(&[
            "stream",
            "--model",
            s(&model),
            "--input",
            s(&data.join(file)),
        ]);
        assert_eq!(lines(&text), expected, "{file}");
    }
}

/// A slide's frames as CSV lines stamped in ms (`t_ms` first), with the header line.
fn stamped_lines(frames: &[Vec<f32>]) -> Vec<String> {
    let names: Vec<String> = (0..16).map(|i| format!("c{i}")).collect();
    let mut all = vec![format!("t_ms,{}", names.join(","))];
    for (i, f) in frames.iter().enumerate() {
        let values: Vec<String> = f.iter().map(|v| v.to_string()).collect();
        all.push(format!("{i},{}", values.join(",")));
    }
    all
}

#[test]
fn invalid_utf8_is_a_bad_frame_and_the_stream_goes_on() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &[]);
    let frames = slide_frames(&data, &slides(&data)[0]);
    let clean = csv_text(&frames);
    let mut hostile: Vec<u8> = Vec::new();
    for (i, line) in clean.split_inclusive('\n').enumerate() {
        hostile.extend_from_slice(line.as_bytes());
        if i == 700 {
            hostile.extend_from_slice(b"0.5,\xff\xfe,0.5\n");
        }
    }
    let args = ["--model", s(&model)];
    let (good, _) = stream_stdin(&dir, &args, clean.as_bytes());
    let (out, err) = stream_stdin(&dir, &args, &hostile);
    assert_eq!(streamed(&out), streamed(&good));
    assert_eq!(lines(&out).last().unwrap()["bad_frames"], 1, "{err}");
    assert!(err.contains("line 702: bad frame skipped"), "{err}");
    assert!(err.contains("not UTF-8"), "{err}");
}

#[test]
fn a_stream_joined_mid_line_or_opened_with_garbage_skips_its_first_line() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &[]);
    let frames = slide_frames(&data, &slides(&data)[2]);
    let clean = csv_text(&frames);
    // Garbage before the header (a terminal's escape, bytes that are not text): each line
    // is a bad frame, and the header after them still names the columns.
    let mut garbled = b"\x1b[0m,12\n\xff\xfe\x00\n".to_vec();
    garbled.extend_from_slice(clean.as_bytes());
    let args = ["--model", s(&model)];
    let (good, _) = stream_stdin(&dir, &args, clean.as_bytes());
    let (out, err) = stream_stdin(&dir, &args, &garbled);
    assert_eq!(streamed(&out), streamed(&good));
    assert_eq!(lines(&out).last().unwrap()["bad_frames"], 2, "{err}");
    assert!(err.contains("line 1: bad frame skipped"), "{err}");
    assert!(err.contains("line 2: bad frame skipped"), "{err}");
    // Joined mid-line, without a header: the first line is the tail of a frame.
    let headerless: String = clean.split_inclusive('\n').skip(2).collect();
    let first_frame = clean.lines().nth(1).unwrap();
    let tail = &first_frame[first_frame.len() / 2..];
    let joined = format!("{tail}\n{headerless}");
    let args = ["--model", s(&model), "--no-header"];
    let (good, _) = stream_stdin(&dir, &args, headerless.as_bytes());
    let (out, err) = stream_stdin(&dir, &args, joined.as_bytes());
    assert_eq!(streamed(&out), streamed(&good));
    assert_eq!(lines(&out).last().unwrap()["bad_frames"], 1, "{err}");
    assert!(err.contains("line 1: bad frame skipped"), "{err}");
    assert!(err.contains("cut short"), "{err}");
    // A header that does not fit is still an error, and so are frames that fit no
    // columns, at their second line; an input of nothing but skipped lines too.
    let header = format!("extra,{}", &clean[..clean.find('\n').unwrap()]);
    for (input, says) in [
        (format!("{header}\n"), "line 1: 17 channel columns selected"),
        (format!("{tail}\n{tail}\n"), "line 2:"),
        ("\x1b[0m,12\n".to_string(), "the input ended after 1 lines"),
    ] {
        let file = dir.join("frames.csv");
        std::fs::write(&file, &input).unwrap();
        let err = dir.fails(&["stream", "--model", s(&model), "--input", s(&file)]);
        assert!(err.contains(says), "{input:?}: {err}");
    }
}

#[test]
fn an_overlong_line_is_a_bad_frame_read_in_bounded_memory() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &[]);
    let frames = slide_frames(&data, &slides(&data)[1]);
    let clean = csv_text(&frames);
    let (good, _) = stream_stdin(&dir, &["--model", s(&model)], clean.as_bytes());
    // The binary under a 1 GiB address-space limit, sent a 2 GiB line between two frames:
    // buffered whole, it would not fit.
    let script = r#"ulimit -v 1048576 && exec "$0" stream "$@""#;
    let mut child = Command::new("bash")
        .args([
            "-c",
            script,
            env!("CARGO_BIN_EXE_neurotex"),
            "--model",
            s(&model),
        ])
        .current_dir(dir.path())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        let (head, tail) = clean.split_at(clean.find("\n").unwrap() + 1);
        stdin.write_all(head.as_bytes())?;
        let chunk = "1,".repeat(1 << 19); // 1 MiB
        for _ in 0..2048 {
            stdin.write_all(chunk.as_bytes())?;
        }
        stdin.write_all(b"1\n")?;
        stdin.write_all(tail.as_bytes())
    });
    let out = child.wait_with_output().unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stderr}");
    writer.join().unwrap().unwrap();
    assert_eq!(streamed(&stdout), streamed(&good));
    assert_eq!(lines(&stdout).last().unwrap()["bad_frames"], 1);
    assert!(stderr.contains("line 2: bad frame skipped"), "{stderr}");
    assert!(stderr.contains("longer than"), "{stderr}");
}

#[test]
fn a_stamp_jump_costs_one_frame_and_huge_stamps_are_refused() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &[]);
    let frames = slide_frames(&data, &slides(&data)[5]);
    let clean = stamped_lines(&frames);
    let args = ["--model", s(&model)];
    let (good, _) = stream_stdin(&dir, &args, (clean.join("\n") + "\n").as_bytes());
    // One stamp with a flipped exponent bit, some 2^40 ms ahead; later frames continue
    // the clock before it.
    let mut hostile = clean.clone();
    let jumped = clean[1001].replacen("1000,", "1099511628776,", 1);
    hostile.insert(1002, jumped);
    let (out, err) = stream_stdin(&dir, &args, (hostile.join("\n") + "\n").as_bytes());
    assert_eq!(streamed(&out), streamed(&good), "{err}");
    assert_eq!(lines(&out).last().unwrap()["bad_frames"], 1, "{err}");
    assert!(err.contains("line 1003: bad frame skipped"), "{err}");

    // Stamps past 2^53 ms cannot be told apart: refused as such, not as equal stamps.
    let mut huge = clean.clone();
    let values = clean[1].split_once(',').unwrap().1;
    huge.insert(1, format!("9007199254740993,{values}"));
    huge.insert(2, format!("9007199254740994,{values}"));
    let (out, err) = stream_stdin(&dir, &args, (huge.join("\n") + "\n").as_bytes());
    assert_eq!(streamed(&out), streamed(&good), "{err}");
    assert_eq!(err.matches("bad frame skipped").count(), 2, "{err}");
    assert!(err.contains("exact range"), "{err}");
    assert!(!err.contains("not after"), "{err}");
}

#[test]
fn a_realtime_replay_survives_stamps_that_are_not_numbers_or_far_ahead() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &[]);
    let frames = slide_frames(&data, &slides(&data)[0]);
    let clean = stamped_lines(&frames[..400]);
    let (good, _) = stream_stdin(
        &dir,
        &["--model", s(&model)],
        (clean.join("\n") + "\n").as_bytes(),
    );
    // After the first frame: a stamp that is not a number, then one an hour ahead.
    let mut text = clean.clone();
    let values = clean[1].split_once(',').unwrap().1;
    text.insert(2, format!("NaN,{values}"));
    text.insert(3, format!("3600000,{values}"));
    let start = std::time::Instant::now();
    let (out, err) = stream_stdin(
        &dir,
        &["--model", s(&model), "--realtime"],
        (text.join("\n") + "\n").as_bytes(),
    );
    // The replay waits for the frame an hour ahead at most --max-gap-s (1 s), then for the
    // 400 ms of frames.
    assert!(start.elapsed().as_secs_f64() < 30.0);
    assert_eq!(streamed(&out), streamed(&good), "{err}");
    assert_eq!(lines(&out).last().unwrap()["bad_frames"], 2, "{err}");
}

#[test]
fn frames_stamped_on_the_1_ms_grid_stream_as_the_same_frames_unstamped() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &[]);
    let frames = slide_frames(&data, &slides(&data)[1]);
    let plain = dir.join("plain.csv");
    std::fs::write(&plain, csv_text(&frames)).unwrap();
    let expected = streamed(&dir.ok(&["stream", "--model", s(&model), "--input", s(&plain)]));
    assert!(expected.len() > 40);
    // ms since an epoch, as a host clock logs them, and ms from 0
    for origin in [1_700_000_000_000u64, 0] {
        let mut lines = stamped_lines(&frames);
        for (i, line) in lines.iter_mut().skip(1).enumerate() {
            let values = line.split_once(',').unwrap().1.to_string();
            *line = format!("{},{values}", origin + i as u64);
        }
        let stamped = dir.join("stamped.csv");
        std::fs::write(&stamped, lines.join("\n") + "\n").unwrap();
        let text = dir.ok(&["stream", "--model", s(&model), "--input", s(&stamped)]);
        assert_eq!(streamed(&text), expected, "stamped from {origin} ms");
    }
}

/// `data`'s spikes exported as an event dataset (`export events EXTRA...`), in `events`.
fn exported(dir: &Dir, data: &Path, extra: &[&str]) -> PathBuf {
    let events = dir.join("events");
    let mut args = vec![
        "export",
        "events",
        "--dataset",
        s(data),
        "--out",
        s(&events),
    ];
    args.extend_from_slice(extra);
    dir.ok(&args);
    events
}

/// An exported event recording as a stream's text: its lines, then a tick at its duration
/// (the manifest's `duration_s`, in ms), so the stream's episode is the recording's length.
fn event_text(events: &Path, file: &str) -> String {
    let manifest = std::fs::read_to_string(events.join("manifest.csv")).unwrap();
    let row = manifest
        .lines()
        .find(|l| l.starts_with(file))
        .expect("the recording's row");
    let duration_s: f64 = row.rsplit(',').next().unwrap().parse().unwrap();
    let text = std::fs::read_to_string(events.join(file)).unwrap();
    format!("{text}{}\n", (duration_s * 1000.0).round())
}

/// The same events as binary records (t in µs); a tick's record has kind 1.
fn event_records(text: &str) -> Vec<u8> {
    let mut out = Vec::new();
    for line in text.lines().skip(1) {
        let f: Vec<i64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        out.extend_from_slice(&(f[0] * 1000).to_le_bytes());
        let (x, y, p, kind) = match f.len() {
            1 => (0, 0, 0, 1u8),
            _ => (f[1] as u16, f[2] as u16, f[3] as i8, 0),
        };
        out.extend_from_slice(&x.to_le_bytes());
        out.extend_from_slice(&y.to_le_bytes());
        out.push(p as u8);
        out.push(kind);
        out.extend_from_slice(&[0, 0]);
    }
    out
}

#[test]
fn a_recordings_spikes_as_events_stream_as_its_samples() {
    // A causal SA+FA model; its spikes exported as events with the same causal pipeline.
    // Streamed as text lines and as binary records, the events give the lines the samples
    // give (`predict --causal`, which equals the frames' stream), bit for bit.
    let dir = Dir::new();
    let (data, model) = trained(&dir, &["--encoding", "sa+fa"]);
    let events = exported(&dir, &data, &["--causal", "--encoding", "sa+fa"]);
    let names: Vec<String> = std::fs::read_dir(&events)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".csv") && n != "manifest.csv")
        .collect();
    for (i, row) in slides(&data)
        .iter()
        .enumerate()
        .filter(|(i, _)| [1, 6].contains(i))
    {
        let expected = predicted(&dir, &model, &data, &row.0);
        assert!(expected.len() > 40);
        let name = names
            .iter()
            .find(|n| n.starts_with(&format!("{i:05}_")))
            .unwrap();
        let text = event_text(&events, name);
        let as_text = [
            "--model",
            s(&model),
            "--format",
            "events",
            "--time-unit",
            "ms",
            "--origin",
            "zero",
        ];
        let (out, err) = stream_stdin(&dir, &as_text, text.as_bytes());
        assert_eq!(lines(&out), expected, "{name}: {err}");
        assert!(
            err.contains("0 bad event(s) skipped, 1 episode(s)"),
            "{err}"
        );
        let records = event_records(&text);
        let as_records = [
            "--model",
            s(&model),
            "--format",
            "events-bin",
            "--origin",
            "zero",
        ];
        let (out, _) = stream_stdin(&dir, &as_records, &records);
        assert_eq!(lines(&out), expected, "{name} as records");
        // Bad events are counted, named and skipped; the rest stream as before.
        let mut bad: Vec<&str> = text.lines().collect();
        bad.insert(3, "6,9,0,1");
        bad.insert(5, "6,1,1,7");
        bad.insert(7, "not,an,event,line");
        bad.insert(9, "2,1,1,1");
        let (out, err) = stream_stdin(&dir, &as_text, (bad.join("\n") + "\n").as_bytes());
        let mut clean = expected.clone();
        for l in &mut clean {
            l.as_object_mut().unwrap().remove("bad_frames");
        }
        assert_eq!(streamed(&out), clean, "{err}");
        assert_eq!(lines(&out).last().unwrap()["bad_frames"], 4, "{err}");
        for said in [
            "line 4",
            "outside the 4x4 grid",
            "line 6",
            "polarity 7",
            "line 8",
            "line 10",
            "before the previous event",
        ] {
            assert!(err.contains(said), "{said}: {err}");
        }
    }
}

#[test]
fn an_event_stream_joined_mid_line_skips_its_first_line() {
    let dir = Dir::new();
    let (data, model) = trained(&dir, &["--encoding", "sa+fa"]);
    let events = exported(&dir, &data, &["--causal", "--encoding", "sa+fa"]);
    let name = std::fs::read_dir(&events)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .find(|n| n.ends_with(".csv") && n != "manifest.csv")
        .unwrap();
    let text = event_text(&events, &name);
    let body: Vec<&str> = text.lines().skip(1).collect();
    // The stream as it is after its first event, with a header ...
    let clean = format!("t,x,y,p\n{}\n", body[1..].join("\n"));
    // ... and joined mid-line: a garbled line, then the first event without its time
    // (`x,y,p`, which reads as an event of three fields), then the rest without a header.
    let cut = &body[0][body[0].find(',').unwrap() + 1..];
    let joined = format!("\x1b[0m,garbage\n{cut}\n{}\n", body[1..].join("\n"));
    let args = [
        "--model",
        s(&model),
        "--format",
        "events",
        "--time-unit",
        "ms",
    ];
    let (good, _) = stream_stdin(&dir, &args, clean.as_bytes());
    let (out, err) = stream_stdin(&dir, &args, joined.as_bytes());
    assert!(lines(&good).len() > 10);
    assert_eq!(streamed(&out), streamed(&good), "{err}");
    assert_eq!(lines(&out).last().unwrap()["bad_frames"], 2, "{err}");
    assert!(
        err.contains("line 1") && err.contains("neither a header nor an event"),
        "{err}"
    );
    assert!(err.contains("line 2") && err.contains("cut short"), "{err}");
}

#[test]
fn a_model_trained_on_events_streams_events_and_refuses_frames() {
    let dir = Dir::new();
    let (data, causal) = trained(&dir, &[]);
    let events = exported(&dir, &data, &[]);
    let model = dir.join("events_model.json");
    dir.ok(&["train", "--dataset", s(&events), "--out", s(&model)]);
    let name = "00001_FT1_v10_t01.csv";
    // The model knows its events' unit and origin: none need saying. With a window longer
    // than the recording, the episode's end classifies all of it, as `predict` does.
    let text = event_text(&events, name);
    let args = [
        "--model",
        s(&model),
        "--format",
        "events",
        "--window-s",
        "60",
    ];
    let (out, _) = stream_stdin(&dir, &args, text.as_bytes());
    let table_path = dir.join("p.csv");
    dir.ok(&[
        "predict",
        "--model",
        s(&model),
        "--dataset",
        s(&events),
        "--out",
        s(&table_path),
    ]);
    let table = std::fs::read_to_string(&table_path).unwrap();
    let offline = table.lines().find(|l| l.contains(name)).unwrap();
    let all = lines(&out);
    assert!(all.len() > 40, "a line every 200 ms");
    let label = all.last().unwrap()["label"].as_str().unwrap().to_string();
    assert!(
        offline.split(',').any(|f| f == label),
        "{offline} / {label}"
    );
    // Its offline twin, `predict --causal` on the event dataset: the same lines.
    let args = ["--model", s(&model), "--format", "events"];
    let (out, _) = stream_stdin(&dir, &args, text.as_bytes());
    assert_eq!(lines(&out), predicted(&dir, &model, &events, name));
    // So does a spiking network trained on the events, run step by step on them.
    let snn = dir.join("snn.json");
    dir.ok(&[
        "train",
        "--dataset",
        s(&events),
        "--classifier",
        "snn",
        "--out",
        s(&snn),
    ]);
    let (out, _) = stream_stdin(
        &dir,
        &["--model", s(&snn), "--format", "events"],
        text.as_bytes(),
    );
    assert_eq!(lines(&out), predicted(&dir, &snn, &events, name));
    let frames = dir.join("frames.csv");
    std::fs::write(&frames, csv_text(&slide_frames(&data, &slides(&data)[1]))).unwrap();
    let err = dir.fails(&["stream", "--model", s(&model), "--input", s(&frames)]);
    assert!(err.contains("trained on address events"), "{err}");
    // A sampled model's text events need their unit.
    let err = dir.fails(&[
        "stream",
        "--model",
        s(&causal),
        "--format",
        "events",
        "--input",
        s(&frames),
    ]);
    assert!(err.contains("--time-unit"), "{err}");
    let err = dir.fails(&[
        "stream",
        "--model",
        s(&causal),
        "--format",
        "events",
        "--time-unit",
        "ms",
        "--stamped",
    ]);
    assert!(err.contains("--stamped"), "{err}");
    // LSL options are checked before any stream is looked for.
    let err = dir.fails(&[
        "stream",
        "--model",
        s(&causal),
        "--input",
        "lsl:x",
        "--lsl-timeout-s",
        "nan",
    ]);
    assert!(err.contains("lsl-timeout-s"), "{err}");
    let err = dir.fails(&["stream", "--model", s(&causal), "--publish", "tcp://x"]);
    assert!(err.contains("--publish takes lsl:NAME"), "{err}");
}
