//! MCAP read throughput (drift-recording's reader: decode and validate every message) on one
//! simulated recording of 1.2 M samples (simulated in set-up, untimed): from the file, and from
//! bytes already in memory (no file I/O).

#[path = "common/campaign.rs"]
mod campaign;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use drift_recording::{read_recording, read_recording_bytes};

fn bench(c: &mut Criterion) {
    let simulated = campaign::simulate(&campaign::read_campaign());
    let path = simulated.files.first().expect("one recording").clone();
    let samples: u64 = read_recording(&path)
        .expect("read")
        .segments
        .iter()
        .map(|s| s.len() as u64)
        .sum();
    let bytes = std::fs::read(&path).expect("bytes");

    let mut group = c.benchmark_group("read_recording");
    group.throughput(Throughput::Elements(samples));
    group.sample_size(20);
    group.bench_function("from_file", |b| {
        b.iter(|| read_recording(black_box(&path)).expect("read"))
    });
    group.bench_function("from_memory", |b| {
        b.iter(|| read_recording_bytes(&path, black_box(&bytes)).expect("read"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
