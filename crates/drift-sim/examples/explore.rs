//! Scratch: print per-activation rise and drift/rise ratio for a small campaign.
use drift_sim::*;
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let noise: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.0);
    let mut c = Campaign::default();
    c.units = 1;
    c.set_points_celsius = vec![30.0];
    c.noise_scale = noise;
    let p = c.protocol.as_mut().unwrap();
    p.intervals_min = vec![1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 30.0];
    p.repeats = 1;
    let dir = std::env::temp_dir().join("explore");
    let t = std::time::Instant::now();
    let s = simulate_campaign(&c, &dir, |_| {})?;
    println!(
        "simulated {} samples in {:?}, {} bytes",
        s.samples,
        t.elapsed(),
        s.recording_bytes
    );
    let recs = read_campaign_dir(&dir)?;
    for seg in &recs[0].segments {
        let n = seg.len();
        let w = 1000;
        let mean = |v: &[f32], a: usize, b: usize| {
            v[a..b].iter().map(|&x| f64::from(x)).sum::<f64>() / (b - a) as f64
        };
        let mut line = format!(
            "int {:>4} act {} ",
            seg.labels.interval_min.unwrap(),
            seg.labels.activation
        );
        for axis in 0..3 {
            let t0 = seg.temperature_raw[axis][..10]
                .iter()
                .map(|&x| f64::from(x))
                .sum::<f64>()
                / 10.0
                / 200.0;
            let tr: Vec<f32> = seg.temperature_raw[axis]
                .iter()
                .map(|&x| x as f32 / 200.0)
                .collect();
            let g0 = mean(&seg.rate_dps[axis], 0, 10);
            let mut s = String::new();
            for &ts in &[10usize, 30, 60, 119] {
                let i = ts * 1000;
                let rise = mean(&tr, i - w / 2, i + w / 2) - t0;
                let g = mean(&seg.rate_dps[axis], i - w / 2, i + w / 2) - g0;
                s += &format!("{rise:5.2}/{:+.4}/{:+.5} ", g, g / rise);
            }
            line += &format!("| T0 {t0:6.2} {s}");
            let _ = n;
        }
        println!("{line}");
    }
    Ok(())
}
