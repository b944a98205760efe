//! Address events through the stream classifier, one thread: 10^5 events of a 4x4 sensor
//! over 12 s (both polarities, about 8 a millisecond, as FabricSlide's encoded spikes), read
//! as 16-byte binary records and as text lines and classified at every 200 ms bin by a
//! 3D-GLCM + KNN model of SA (ON) and FA (OFF) spikes. The target is 10^7 events/s.

mod support;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use neurotex::events::{EventsFormat, Origin};
use neurotex::pipeline::{Encoding, PipelineParams};
use neurotex::recording::TimeUnit;
use neurotex::saved::SavedModel;
use neurotex::stream::events::{feed_events, EventEncoding, EventReader, EventSource};
use neurotex::stream::frames::Sink;
use neurotex::stream::{Event, StreamClassifier, StreamParams};
use rand::{Rng, SeedableRng};
use support::made_up_model;

const EVENTS: usize = 100_000;

/// The events as records and as text lines: times in µs, sorted, over 12 s.
fn events() -> (Vec<u8>, Vec<u8>) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut t: Vec<i64> = (0..EVENTS).map(|_| rng.gen_range(0..12_000_000)).collect();
    t.sort_unstable();
    let (mut records, mut text) = (Vec::new(), b"t,x,y,p\n".to_vec());
    for t in t {
        let (x, y, p) = (
            rng.gen_range(0..4u16),
            rng.gen_range(0..4u16),
            rng.gen_range(0..2u8),
        );
        records.extend_from_slice(&t.to_le_bytes());
        records.extend_from_slice(&x.to_le_bytes());
        records.extend_from_slice(&y.to_le_bytes());
        records.extend_from_slice(&[p, 0, 0, 0]);
        text.extend_from_slice(format!("{t},{x},{y},{p}\n").as_bytes());
    }
    (records, text)
}

/// Counts the decisions.
struct Count(usize);

impl Sink for Count {
    fn events(&mut self, _: &StreamClassifier, events: &[Event]) -> neurotex::Result<()> {
        self.0 += events.len();
        Ok(())
    }
    fn bad_frame(&mut self, place: &str, why: &str) {
        panic!("{place}: {why}");
    }
}

fn bench(c: &mut Criterion) {
    let params = PipelineParams {
        encoding: Encoding::SaFa,
        ..PipelineParams::default()
    };
    let model = SavedModel::from(made_up_model(4, &params));
    let (records, text) = events();
    let mut group = c.benchmark_group("stream_events");
    group.throughput(Throughput::Elements(EVENTS as u64));
    group.sample_size(20);
    for (name, encoding, bytes) in [
        ("records_1e5", EventEncoding::Binary, &records),
        ("text_1e5", EventEncoding::Text, &text),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut format = EventsFormat::new(TimeUnit::Microseconds);
                format.origin = Origin::Zero;
                let source = EventSource::for_model(
                    &model,
                    Some(TimeUnit::Microseconds),
                    Some(Origin::Zero),
                    false,
                )
                .unwrap();
                let params = StreamParams::for_model(&model);
                let mut stream =
                    StreamClassifier::for_events(model.clone(), params, source).unwrap();
                let mut reader = EventReader::new(&bytes[..], "bench", encoding, &format);
                let mut sink = Count(0);
                feed_events(&mut reader, &mut stream, None, &mut sink, &|| false).unwrap();
                assert!(sink.0 >= 59, "a decision every 200 ms");
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
