//! Prints, per activation, the sensor rise, the drift and their ratio at 10/30/60/119 s for
//! one unit at +30 °C (the paper's Fig. 3–4 in numbers), reading the recording back.
//!
//! `cargo run --release -p drift-sim --example ratios -- [noise_scale]`

use drift_sim::{read_campaign_dir, simulate_campaign, Campaign};

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let noise: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(1.0);
    let mut c = Campaign {
        units: 1,
        set_points_celsius: vec![30.0],
        noise_scale: noise,
        ..Campaign::default()
    };
    if let Some(p) = c.protocol.as_mut() {
        p.repeats = 1;
    }
    let dir = tempfile_dir();
    let summary = simulate_campaign(&c, &dir, |_| {})?;
    println!(
        "{} samples in {:.2} s, {} bytes",
        summary.samples, summary.wall_s, summary.recording_bytes
    );
    for seg in &read_campaign_dir(&dir)?[0].segments {
        let mut line = format!(
            "interval {:>4} min, activation {}",
            seg.labels.interval_min.unwrap_or(f64::NAN),
            seg.labels.activation
        );
        for axis in 0..3 {
            let rate: Vec<f64> = seg.rate_dps[axis].iter().map(|&x| f64::from(x)).collect();
            let temp: Vec<f64> = (0..seg.len())
                .filter_map(|i| seg.temperature_celsius(axis, i))
                .collect();
            let (g0, t0) = (mean(&rate[..500]), mean(&temp[..500]));
            line += " |";
            for s in [10usize, 30, 60, 119] {
                let w = s * 1000 - 500..s * 1000 + 500;
                let (rise, drift) = (mean(&temp[w.clone()]) - t0, mean(&rate[w]) - g0);
                line += &format!(" {rise:4.2}°C {drift:+.4} {:+.5}", drift / rise);
            }
        }
        println!("{line}");
    }
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}

fn tempfile_dir() -> std::path::PathBuf {
    std::env::temp_dir().join(format!("drift-sim-ratios-{}", std::process::id()))
}
