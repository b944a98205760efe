//! `neurotex encode`.

use ndarray::Array3;
use ndarray_npy::{read_npy, write_npy};

use crate::util::{recording, s, Dir};

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
