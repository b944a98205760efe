//! Reading one address-event recording into spike trains: 10^5 events on a 4x4 grid, two
//! polarities, 12 s, as tonic's `.npy` (microseconds) and as CSV (milliseconds). A
//! FabricSlide-sized dataset of such recordings through `features` is timed in
//! docs/event-sensors.md.

use criterion::{criterion_group, criterion_main, Criterion};
use neurotex::events::{read_events, write_events, Event, EventFile, EventGrid, EventsFormat};

fn events(n: u32) -> Vec<Event> {
    let mut state = 0x9e37_79b9_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state
    };
    let mut out: Vec<Event> = (0..n)
        .map(|_| Event {
            t_ms: next() % 12_000,
            y: next() % 4,
            x: next() % 4,
            p: (next() % 2) as u8,
        })
        .collect();
    out.sort_unstable();
    out
}

fn bench(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("neurotex-bench-events-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let grid = EventGrid {
        rows: 4,
        cols: 4,
        present: vec![true; 16],
        taxels: (0..16).collect(),
    };
    let recording = events(100_000);
    for kind in [EventFile::Npy, EventFile::Csv] {
        let path = dir.join(format!("e.{}", kind.extension()));
        let mut bytes = Vec::new();
        write_events(&mut bytes, &recording, kind).expect("written");
        std::fs::write(&path, bytes).expect("written");
        let format = EventsFormat::new(kind.time_unit());
        let name = format!("events/read/{}/1e5", kind.extension());
        c.bench_function(&name, |b| {
            b.iter(|| read_events(&path, &format, &grid, Some(12_000), 3_600_000).expect("read"))
        });
    }
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);
