//! The closed-loop experiment of `docs/closed-loop.md`: for each hidden simulator effect (and for
//! none), simulate a campaign with that effect switched on and the fitter told nothing; fit the
//! paper's tables on the +30/+40 °C protocol activations; diagnose the residual on unseen
//! field-like activations at +33 °C; turn the significant winners into the extended model's terms,
//! fit their coefficients on field-like activations recorded at the calibration ambients and refit
//! the tables; report the error before and after on the +33 °C activations beside the noise floor
//! of a zero-drift twin unit recorded the same way.
//!
//! ```sh
//! cargo run --release --example closed_loop -- [--seeds 1] [--first-seed 1] [--sessions 6] \
//!     [--scale 1] [--effects thermal_lag,supply_voltage]
//! ```
//!
//! The fitter never reads the ground truth; the effect's name is only used to label the row.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Context;
use drift_fit::analyse::analyse;
use drift_fit::diagnose::{diagnose, series, AxisDiagnosis};
use drift_fit::evaluate::{self, switch_on_raw};
use drift_fit::extend::{correct_with_terms, extend, TermPlan};
use drift_fit::{fit_unit, FitSettings};
use drift_recording::{read_recording, Segment, SeriesKind};
use drift_sim::{simulate_campaign, Campaign, Field, HiddenEffects, Protocol, UnitModel};

const CALIBRATION: [f64; 2] = [30.0, 40.0];
const VALIDATION: f64 = 33.0;

/// Field-like use without ambient ramps or carried units (the paper's own field gap, reported
/// on its own row): random off-times, supply voltage and orientation changing per activation,
/// each sensor's heating scattering.
fn field(sessions: u32) -> Field {
    Field {
        sessions,
        activations: 8,
        ambient_ramp_c_per_min: 0.0,
        carry_probability: 0.0,
        ..Field::default()
    }
}

/// Multiplies every switched-on effect's magnitude by `scale` (1 = the simulator's defaults).
fn scaled(mut effects: HiddenEffects, scale: f64) -> HiddenEffects {
    if let Some(e) = &mut effects.thermal_lag {
        e.dps_per_c_per_s *= scale;
    }
    if let Some(e) = &mut effects.acceleration {
        e.dps_per_g *= scale;
    }
    if let Some(e) = &mut effects.supply_voltage {
        e.dps_per_v *= scale;
    }
    if let Some(e) = &mut effects.cross_axis {
        e.w_per_k *= scale;
    }
    if let Some(e) = &mut effects.rise_nonlinearity {
        e.per_c *= scale;
    }
    if let Some(e) = &mut effects.ageing {
        e.offset_dps_per_day *= scale;
        e.tempco_relative_per_day *= scale;
    }
    effects
}

fn campaign(
    seed: u64,
    effect: &str,
    unit_model: UnitModel,
    plan: &Plan,
) -> anyhow::Result<Campaign> {
    let mut effects = HiddenEffects::default();
    let mut field = field(plan.sessions);
    match effect {
        "none" => {}
        "ambient_ramp" => {
            field = Field {
                sessions: plan.sessions,
                ..Field::default()
            }
        }
        name => effects.enable(name).map_err(anyhow::Error::msg)?,
    }
    let effects = scaled(effects, plan.scale);
    // The zero-drift twin only needs its field sessions (the floor); a short protocol keeps the
    // campaign valid.
    let protocol = if unit_model == UnitModel::ZeroSystematicDrift {
        Protocol {
            intervals_min: vec![30.0],
            repeats: 1,
            ..Protocol::default()
        }
    } else {
        Protocol {
            intervals_min: vec![1.0, 2.0, 5.0, 10.0, 30.0],
            repeats: 2,
            ..Protocol::default()
        }
    };
    Ok(Campaign {
        name: format!("closed-loop-{effect}"),
        seed,
        units: 1,
        unit_model,
        protocol: Some(protocol),
        field: Some(field),
        effects: if unit_model == UnitModel::ZeroSystematicDrift {
            HiddenEffects::default()
        } else {
            effects
        },
        truth_bias: drift_sim::campaign::TruthBias::AuxRate,
        ..Campaign::default()
    })
}

fn segments(dir: &Path) -> anyhow::Result<Vec<Segment>> {
    let mut out = Vec::new();
    for path in drift_fit::pipeline::recording_files(dir)? {
        out.extend(read_recording(&path)?.segments);
    }
    Ok(out)
}

fn is(set_point: f64, value: f64) -> bool {
    (set_point - value).abs() < 1e-6
}

/// (max − min, RMS) of the 1-s mean of each axis (the evaluation's own metric).
fn metric(rates: &[Vec<f32>; 3], window: usize) -> [(f64, f64); 3] {
    let (drift, rms) = evaluate::metric(rates, window);
    std::array::from_fn(|a| (drift[a], rms[a]))
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len().max(1) as f64
}

/// One row of the table: one effect, one seed, one axis.
struct Row {
    effect: String,
    seed: u64,
    axis: &'static str,
    top: String,
    significant: bool,
    terms: String,
    before: (f64, f64),
    after: (f64, f64),
    floor: (f64, f64),
    field_activations: usize,
}

/// The experiment's size.
struct Plan {
    /// Field sessions per set point (8 activations each).
    sessions: u32,
    /// Effect magnitude relative to the simulator's defaults.
    scale: f64,
}

fn run(
    effect: &str,
    seed: u64,
    work: &Path,
    settings: &FitSettings,
    plan_size: &Plan,
) -> anyhow::Result<Vec<Row>> {
    let dir = work.join(format!("{effect}-{seed}"));
    let twin_dir = work.join(format!("{effect}-{seed}-floor"));
    simulate_campaign(
        &campaign(seed, effect, UnitModel::Physical, plan_size)?,
        &dir,
        |_| {},
    )
    .with_context(|| format!("simulating {effect}"))?;
    simulate_campaign(
        &campaign(seed, effect, UnitModel::ZeroSystematicDrift, plan_size)?,
        &twin_dir,
        |_| {},
    )?;
    let all = segments(&dir)?;
    let calibration: Vec<&Segment> = all
        .iter()
        .filter(|s| {
            s.labels.series_kind == SeriesKind::Protocol
                && CALIBRATION
                    .iter()
                    .any(|&c| is(c, s.labels.set_point_celsius))
        })
        .collect();
    let training: Vec<&Segment> = all
        .iter()
        .filter(|s| {
            s.labels.series_kind == SeriesKind::Field
                && CALIBRATION
                    .iter()
                    .any(|&c| is(c, s.labels.set_point_celsius))
        })
        .collect();
    let validation: Vec<&Segment> = all
        .iter()
        .filter(|s| {
            s.labels.series_kind == SeriesKind::Field && is(VALIDATION, s.labels.set_point_celsius)
        })
        .collect();
    let analysed = calibration
        .iter()
        .map(|s| analyse(s, settings))
        .collect::<Result<Vec<_>, _>>()?;
    let base = fit_unit(&analysed, settings)?;
    let prepared: Vec<_> = validation
        .iter()
        .map(|s| series(&base, s, settings))
        .collect();
    let axes: [AxisDiagnosis; 3] = diagnose(&prepared);
    let plan = TermPlan::choose(&axes);
    let extended = if plan.terms.is_empty() {
        None
    } else {
        Some(extend(&base, &plan, &calibration, &training, settings, 2)?)
    };

    let window = settings.lowpass_window_samples;
    let mut before: [Vec<(f64, f64)>; 3] = Default::default();
    let mut after: [Vec<(f64, f64)>; 3] = Default::default();
    for segment in &validation {
        let on = switch_on_raw(segment, settings);
        let plain = metric(
            &correct_with_terms(&base.modified, &plan, segment, on),
            window,
        );
        let ext = match &extended {
            Some(e) => metric(&correct_with_terms(&e.tables, &e.plan, segment, on), window),
            None => plain,
        };
        for a in 0..3 {
            before[a].push(plain[a]);
            after[a].push(ext[a]);
        }
    }
    // Noise floor: the zero-drift twin's field activations at +33 °C, uncorrected, less the unit's
    // constant bias (the mean over all its activations): what a perfect model would leave.
    let twin = segments(&twin_dir)?;
    let twin_field: Vec<&Segment> = twin
        .iter()
        .filter(|s| {
            s.labels.series_kind == SeriesKind::Field && is(VALIDATION, s.labels.set_point_celsius)
        })
        .collect();
    let offset: [f64; 3] = std::array::from_fn(|a| {
        mean(
            &twin_field
                .iter()
                .map(|s| {
                    s.rate_dps[a].iter().map(|&v| f64::from(v)).sum::<f64>() / s.len().max(1) as f64
                })
                .collect::<Vec<_>>(),
        )
    });
    let mut floor: [Vec<(f64, f64)>; 3] = Default::default();
    for s in &twin_field {
        let centred: [Vec<f32>; 3] = std::array::from_fn(|a| {
            s.rate_dps[a]
                .iter()
                .map(|&v| (f64::from(v) - offset[a]) as f32)
                .collect()
        });
        let m = metric(&centred, window);
        for a in 0..3 {
            floor[a].push(m[a]);
        }
    }
    let terms = if plan.terms.is_empty() {
        "–".to_owned()
    } else {
        plan.terms
            .iter()
            .map(|t| t.candidate.clone())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let avg = |v: &[(f64, f64)]| {
        (
            mean(&v.iter().map(|p| p.0).collect::<Vec<_>>()),
            mean(&v.iter().map(|p| p.1).collect::<Vec<_>>()),
        )
    };
    Ok((0..3)
        .map(|a| {
            let top = axes[a].ranking.first();
            Row {
                effect: effect.to_owned(),
                seed,
                axis: axes[a].axis,
                top: top.map_or("–".into(), |c| c.name.clone()),
                significant: top.is_some_and(|c| c.significant),
                terms: terms.clone(),
                before: avg(&before[a]),
                after: avg(&after[a]),
                floor: avg(&floor[a]),
                field_activations: validation.len(),
            }
        })
        .collect())
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let seeds: u64 = value("--seeds").map_or(Ok(1), |s| s.parse())?;
    let first_seed: u64 = value("--first-seed").map_or(Ok(1), |s| s.parse())?;
    let size = Plan {
        sessions: value("--sessions").map_or(Ok(6), |s| s.parse())?,
        scale: value("--scale").map_or(Ok(1.0), |s| s.parse())?,
    };
    let effects: Vec<String> = value("--effects").map_or_else(
        || {
            [
                "none",
                "thermal_lag",
                "acceleration",
                "supply_voltage",
                "cross_axis",
                "rise_nonlinearity",
                "ageing",
                "ambient_ramp",
            ]
            .map(String::from)
            .to_vec()
        },
        |s| s.split(',').map(String::from).collect(),
    );
    let work = tempfile::tempdir()?;
    let settings = FitSettings::default();
    let mut rows = Vec::new();
    println!("| effect | seed | axis | top candidate | significant | terms added | RMS before | RMS after | noise floor RMS | excess cut | drift before | drift after | noise floor drift |");
    println!("|---|---:|---|---|:---:|---|---:|---:|---:|---:|---:|---:|---:|");
    for effect in &effects {
        for seed in first_seed..first_seed + seeds {
            eprintln!("{effect}, seed {seed} …");
            let new = run(effect, seed, work.path(), &settings, &size)?;
            // Printed as each run ends: a long experiment keeps what it has measured.
            for r in &new {
                let cut = (r.before.1 - r.floor.1) / (r.after.1 - r.floor.1).max(1e-9);
                println!(
                    "| {} | {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.1}× | {:.4} | {:.4} | {:.4} |",
                    r.effect,
                    r.seed,
                    r.axis,
                    r.top,
                    if r.significant { "yes" } else { "no" },
                    r.terms,
                    r.before.1,
                    r.after.1,
                    r.floor.1,
                    cut,
                    r.before.0,
                    r.after.0,
                    r.floor.0,
                );
            }
            rows.extend(new);
            // Recordings of finished runs are not needed again.
            for suffix in ["", "-floor"] {
                let _ =
                    std::fs::remove_dir_all(work.path().join(format!("{effect}-{seed}{suffix}")));
            }
        }
    }
    let mut null: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.effect == "none") {
        let e = null.entry("none").or_default();
        e.0 += usize::from(!r.significant);
        e.1 += 1;
    }
    if let Some((quiet, total)) = null.get("none") {
        println!(
            "\nnull case: nothing significant on {quiet} of {total} axes × seeds ({:.0} %); {} field activations per run",
            100.0 * *quiet as f64 / (*total).max(1) as f64,
            rows.first().map_or(0, |r| r.field_activations)
        );
    }
    Ok(())
}
