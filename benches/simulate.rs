//! Simulate-and-record throughput: one unit, one set point, the paper's protocol at one
//! interval (5 activations × 2 min × 1000 Hz = 600 000 samples per iteration), into zstd MCAP.
//!
//! `cargo bench --bench simulate` ; figures go to docs/performance.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use drift_sim::campaign::TruthBias;
use drift_sim::{simulate_campaign, Campaign};

fn campaign() -> Campaign {
    let mut c = Campaign {
        units: 1,
        set_points_celsius: vec![30.0],
        ..Campaign::default()
    };
    if let Some(p) = c.protocol.as_mut() {
        p.intervals_min = vec![5.0];
        p.repeats = 1;
    }
    c
}

fn simulate_and_record(crit: &mut Criterion) {
    let c = campaign();
    let samples = drift_sim::simulate::total_samples(&c);
    let dir = tempfile::tempdir().expect("temp dir");
    let mut group = crit.benchmark_group("simulate_and_record");
    group.throughput(Throughput::Elements(samples));
    group.sample_size(10);
    // Default: recording (zstd) + ground truth with the true bias of every sample (lz4).
    group.bench_function("recording_and_per_sample_truth", |b| {
        b.iter(|| simulate_campaign(&c, dir.path(), |_| {}).expect("simulate"));
    });
    // Truth at the 100 Hz auxiliary rate: the recording dominates the cost.
    let aux = Campaign {
        truth_bias: TruthBias::AuxRate,
        ..c.clone()
    };
    group.bench_function("recording_and_100hz_truth", |b| {
        b.iter(|| simulate_campaign(&aux, dir.path(), |_| {}).expect("simulate"));
    });
    group.finish();
}

criterion_group!(benches, simulate_and_record);
criterion_main!(benches);
