//! `neurotex encode`.

use ndarray::Array3;
use ndarray_npy::{read_npy, write_npy};

use crate::util::{recording, s, xorshift, Dir};

#[test]
fn encode_writes_raster_and_events() {
    let dir = Dir::new();
    let input = dir.join("in.npy");
    write_npy(&input, &recording(500, 80.0, 0.3, 1)).unwrap();
    let out = dir.join("spikes.npy");
    let events = dir.join("events.csv");
    dir.ok(&[
        "encode",
        s(&input),
        "--out",
        s(&out),
        "--events",
        s(&events),
    ]);
    let raster: Array3<u8> = read_npy(&out).unwrap();
    assert_eq!(raster.shape(), &[500, 4, 4]);
    let spikes = raster.iter().filter(|&&v| v == 1).count();
    assert!(spikes > 0 && raster.iter().all(|&v| v <= 1));
    let text = std::fs::read_to_string(&events).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t_ms,row,col"));
    let ev: Vec<Vec<usize>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(ev.len(), spikes);
    assert!(ev.iter().all(|e| raster[[e[0], e[1], e[2]]] == 1));
    // a CSV at 500 Hz is resampled onto 1 ms steps
    let csv = dir.join("in.csv");
    let mut text = String::from("t_s,a,b\n");
    for i in 0..400 {
        text.push_str(&format!(
            "{},{},{}\n",
            i as f64 / 500.0,
            (i as f64 / 10.0).sin() + 1.0,
            0.5
        ));
    }
    std::fs::write(&csv, text).unwrap();
    let out2 = dir.join("csv.npy");
    dir.ok(&["encode", s(&csv), "--out", s(&out2)]);
    let raster: Array3<u8> = read_npy(&out2).unwrap();
    assert_eq!(raster.shape(), &[799, 1, 2]);
}

#[test]
fn encode_takes_the_rate_from_a_layout_unless_fs_is_given() {
    let dir = Dir::new();
    let input = dir.join("in.npy");
    write_npy(&input, &recording(400, 80.0, 0.3, 2)).unwrap();
    let layout = dir.join("layout.toml");
    std::fs::write(&layout, "fs = 500.0\n").unwrap();
    let out = dir.join("a.npy");
    // encodes with the layout and `extra`; returns the raster's time steps
    let steps = |extra: &[&str]| {
        let mut args = vec![
            "encode",
            s(&input),
            "--out",
            s(&out),
            "--layout",
            s(&layout),
        ];
        args.extend_from_slice(extra);
        dir.ok(&args);
        read_npy::<_, Array3<u8>>(&out).unwrap().shape()[0]
    };
    assert_eq!(steps(&[]), 799, "400 samples at 500 Hz span 798 ms");
    assert_eq!(steps(&["--fs", "1000"]), 400);
    let err = dir.fails(&["encode", s(&input), "--out", s(&out), "--fs", "-5"]);
    assert!(err.contains("--fs"), "{err}");
}

/// Izhikevich's regular-spiking neuron (a, b, c, d = 0.02, 0.2, -65, 8) written out step by
/// step as in his 2003 listing (spike check and reset first, then two 0.5 ms half-steps of
/// `v` and one 1 ms step of `u`), one neuron per column of the time-major `x` (`n` per
/// frame) driven by `gain * x`. Returns the raster, 1 where a neuron spiked.
fn reference_spikes(x: &[f64], n: usize, gain: f64) -> Vec<u8> {
    let (a, b, c, d) = (0.02, 0.2, -65.0, 8.0);
    let mut v = vec![c; n];
    let mut u = vec![b * c; n];
    let mut raster = Vec::with_capacity(x.len());
    for frame in x.chunks_exact(n) {
        for j in 0..n {
            let fired = v[j] >= 30.0;
            raster.push(u8::from(fired));
            if fired {
                v[j] = c;
                u[j] += d;
            }
            let i = gain * frame[j];
            for _ in 0..2 {
                v[j] += 0.5 * (0.04 * (v[j] * v[j]) + 5.0 * v[j] + 140.0 - u[j] + i);
            }
            u[j] += a * (b * v[j] - u[j]);
        }
    }
    raster
}

/// A sample `x` for a recording whose largest sample is `max` such that a neuron at rest
/// driven by `gain * x / max` fires at the next step and one driven by `gain * x * (1 /
/// max)` does not, or the reverse; `None` when no sample within 64 ULPs of the threshold
/// rounds differently under the two.
fn knife_edge(max: f64, gain: f64) -> Option<f64> {
    let fires_from_rest = |q: f64| reference_spikes(&[q, 0.0], 1, gain)[1] == 1;
    // The threshold input by bisection over the bit patterns of positive floats, which
    // order like the floats.
    let (mut lo, mut hi) = (0f64.to_bits(), 1f64.to_bits());
    assert!(
        fires_from_rest(1.0),
        "the gain must make a full input fire at once"
    );
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if fires_from_rest(f64::from_bits(mid)) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let centre = (f64::from_bits(hi) * max).to_bits();
    (centre - 64..centre + 64)
        .map(f64::from_bits)
        .find(|&x| fires_from_rest(x / max) != fires_from_rest(x * (1.0 / max)))
}

#[test]
fn encode_feeds_the_neurons_x_over_its_maximum() {
    // numpy's `x / x.max()` rounds each sample once; multiplying by `1 / max` rounds twice
    // and differs in the last bit for some samples. One sample placed on the firing
    // threshold of a neuron at rest makes that last bit visible in the spikes.
    let gain = 100.0;
    let (steps, channels) = (300, 3);
    let (max, edge) = (0..200)
        .map(|k| 0.7 + 0.0137 * k as f64)
        .find_map(|max| knife_edge(max, gain).map(|x| (max, x)))
        .expect("a sample on the threshold for one of the maxima tried");
    let mut random = xorshift(7);
    let mut x: Vec<f64> = (0..steps * channels)
        .map(|_| max * (random() % 1_000_000) as f64 / 1_000_000.0)
        .collect();
    x[0] = edge;
    x[5 * channels + 2] = max;
    let by_division: Vec<f64> = x.iter().map(|s| s / max).collect();
    let by_inverse: Vec<f64> = x.iter().map(|s| s * (1.0 / max)).collect();
    let expected = reference_spikes(&by_division, channels, gain);
    assert_ne!(
        expected,
        reference_spikes(&by_inverse, channels, gain),
        "the recording must tell the two normalisations apart"
    );

    let dir = Dir::new();
    let input = dir.join("x.npy");
    write_npy(
        &input,
        &Array3::from_shape_vec((steps, 1, channels), x).unwrap(),
    )
    .unwrap();
    let out = dir.join("spikes.npy");
    dir.ok(&[
        "encode",
        s(&input),
        "--out",
        s(&out),
        "--cutoff",
        "0",
        "--gain",
        "100",
    ]);
    let raster: Array3<u8> = read_npy(&out).unwrap();
    assert_eq!(raster.shape(), &[steps, 1, channels]);
    let raster = raster.into_raw_vec_and_offset().0;
    let first = raster.iter().zip(&expected).position(|(a, b)| a != b);
    assert_eq!(
        first.map(|i| (i / channels, i % channels)),
        None,
        "first spike that differs from x / x.max(), as (step, neuron)"
    );
}

/// A raw logger file at 28 ms (about 35.7 Hz): a header, host stamps in ms, a proximity
/// column that is not a taxel, then four channels; the last row is written twice.
fn raw_fabric_log(rows: usize) -> String {
    let mut text = String::from("timestamp, proximity1, channel1, channel2, channel3, channel4\n");
    for k in 0..rows {
        let v = |c: usize| 100 + (k * 7 + c * 13) % 50;
        text.push_str(&format!(
            "{},65535,{},{},{},{}\n",
            4_277_465 + 28 * k,
            v(0),
            v(1),
            v(2),
            v(3)
        ));
    }
    let last = text.lines().last().unwrap().to_string();
    text.push_str(&last);
    text.push('\n');
    text
}

#[test]
fn encode_reads_a_raw_log_with_the_import_options() {
    let dir = Dir::new();
    let log = dir.join("Silk_F1_V10mmps_0.csv");
    std::fs::write(&log, raw_fabric_log(50)).unwrap();
    let out = dir.join("spikes.npy");
    let encode = |extra: &[&str]| {
        let mut args = vec!["encode", s(&log), "--out", s(&out)];
        args.extend_from_slice(extra);
        dir.run(&args)
    };
    let run = encode(&[
        "--time-column",
        "timestamp",
        "--channels",
        r"^channel\d+$",
        "--grid",
        "2x2",
        "--baseline",
        "min",
    ]);
    assert!(run.status.success(), "{}", run.stderr);
    // the time and proximity columns are not taxels, and the 49 intervals of 28 ms
    // are resampled onto 1 ms steps (not read as 50 samples at 1 kHz)
    let raster: Array3<u8> = read_npy(&out).unwrap();
    assert_eq!(raster.shape(), &[49 * 28 + 1, 2, 2]);
    assert!(run.stderr.contains("resampled"), "{}", run.stderr);
    // the same columns by index, headerless: drop the header row
    let text = std::fs::read_to_string(&log).unwrap();
    let headerless = dir.join("raw.csv");
    std::fs::write(
        &headerless,
        text.split_once('\n').unwrap().1.replace(',', "\t"),
    )
    .unwrap();
    let out2 = dir.join("spikes2.npy");
    dir.ok(&[
        "encode",
        s(&headerless),
        "--out",
        s(&out2),
        "--no-header",
        "--time-column",
        "0",
        "--channels",
        "2-5",
        "--grid",
        "2x2",
        "--baseline",
        "min",
    ]);
    let again: Array3<u8> = read_npy(&out2).unwrap();
    assert_eq!(again, raster);
    // with `--duplicate-stamps error` the repeated last row is still only dropped, but
    // a bad column is named
    let err = dir.fails(&[
        "encode",
        s(&headerless),
        "--out",
        s(&out2),
        "--no-header",
        "--channels",
        "2-9",
    ]);
    assert!(
        err.contains("raw.csv") && err.contains("channel column 6 (0-based) does not exist"),
        "{err}"
    );
}

#[test]
fn encode_reads_the_layout_beside_the_recording_unless_given_one() {
    let dir = Dir::new();
    let ds = dir.join("ds");
    std::fs::create_dir(&ds).unwrap();
    let log = ds.join("a.csv");
    std::fs::write(&log, raw_fabric_log(50)).unwrap();
    std::fs::write(
        ds.join("layout.toml"),
        "rows = 2\ncols = 2\ntime_column = \"timestamp\"\nchannels = [\"channel1\", \"channel2\", \"channel3\", \"channel4\"]\n",
    )
    .unwrap();
    let out = dir.join("spikes.npy");
    let run = dir.run(&["encode", s(&log), "--out", s(&out)]);
    assert!(run.status.success(), "{}", run.stderr);
    assert!(
        run.stderr.contains("layout beside the recording"),
        "{}",
        run.stderr
    );
    let raster: Array3<u8> = read_npy(&out).unwrap();
    assert_eq!(raster.shape(), &[49 * 28 + 1, 2, 2]);
    // --layout wins over the file beside the recording: here one row of four channels
    let other = dir.join("other.toml");
    std::fs::write(
        &other,
        "time_column = \"timestamp\"\nchannels = [\"channel1\", \"channel2\", \"channel3\", \"channel4\"]\n",
    )
    .unwrap();
    dir.ok(&["encode", s(&log), "--out", s(&out), "--layout", s(&other)]);
    let raster: Array3<u8> = read_npy(&out).unwrap();
    assert_eq!(raster.shape(), &[49 * 28 + 1, 1, 4]);
    // and options override single settings of the layout
    dir.ok(&["encode", s(&log), "--out", s(&out), "--grid", "4x1"]);
    let raster: Array3<u8> = read_npy(&out).unwrap();
    assert_eq!(raster.shape(), &[49 * 28 + 1, 4, 1]);
    // a layout that names a column the file lacks is an error naming the file
    std::fs::write(ds.join("layout.toml"), "time_column = \"stamp\"\n").unwrap();
    let err = dir.fails(&["encode", s(&log), "--out", s(&out)]);
    assert!(
        err.contains("a.csv") && err.contains("missing time column `stamp`"),
        "{err}"
    );
}
