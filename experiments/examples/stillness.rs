//! The tables, a stillness learner, and both, on field-like activations that move (its table is in
//! docs/stillness.md). Evaluation only: the fit sees the calibration recordings, never the truth;
//! the body rate the simulator added is subtracted afterwards to measure the residual bias.
//!
//! ```sh
//! cargo run --release -p experiments --example stillness -- [--seed 1] [--units 2] [--sessions 3] \
//!     [--json stillness.json]
//! ```
//!
//! Two campaigns with the same seed differ only in their field motion: rotations with still gaps
//! (the simulator's default profile) and rotations without any. Their units, calibration protocols
//! and field schedules are the same draws. The paper's tables are fitted on the protocol at +30 and
//! +40 °C; every field activation (+30, +33, +40 °C) is then corrected three ways through drift-core
//! in f32: the tables alone, the learner alone on the raw rate, and the learner after the tables.
//! The learner starts each activation with no offset (it lives in RAM, as Fusion's does) and reads
//! the accelerometer. Per unit × axis × class (cold start, warm restart: off less than the fit's
//! cool-down) the mean over the cell's activations of the residual bias RMS (RMS of the 1-s moving
//! average of corrected less true rate), °/s; the noise floor is the same RMS on the zero-drift twin
//! with the learner after perfect tables (its rate less the body rate, nothing to remove).
//!
//! The floors: with still gaps, both together leave less than either alone in at least 90 % of
//! the unit × axis × class cells; without, both together leave no more than the tables alone in
//! every cell. `--json` writes every cell and each class's count against its floor.

use anyhow::Context;
use drift_core::{Corrector, StillnessLearner, StillnessSettings};
use drift_evaluate::evaluate::{metric, sample_at, switch_on_raw};
use drift_fit::analyse::analyse;
use drift_fit::{fit_unit, FitSettings};
use drift_recording::{read_recording, Segment, SeriesKind};
use drift_sim::motion::{self, Motion, Rotation};
use drift_sim::schedule::plan;
use drift_sim::{simulate_campaign, Campaign, Field, Protocol, UnitModel};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const CALIBRATION: [f64; 2] = [30.0, 40.0];

/// Tables, learner, and both, against the body rate the simulator added.
#[derive(clap::Parser)]
struct Args {
    /// The campaigns' seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Simulated units.
    #[arg(long, default_value_t = 2)]
    units: u32,
    /// Field sessions per set point (8 activations each).
    #[arg(long, default_value_t = 3)]
    sessions: u32,
    /// Also write the cells and the floors' counts here, as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
}

/// Share of cells in which both together must beat either alone, with still gaps.
const FLOOR_SHARE_WITH_GAPS: f64 = 0.9;

fn campaign(seed: u64, units: u32, sessions: u32, model: UnitModel, gaps: bool) -> Campaign {
    let motion = Motion {
        still_s: if gaps {
            Motion::default().still_s
        } else {
            [0.0, 0.0]
        },
        ..Motion::default()
    };
    Campaign {
        name: format!("stillness-{}", if gaps { "gaps" } else { "no-gaps" }),
        seed,
        units,
        unit_model: model,
        set_points_celsius: vec![30.0, 40.0, 33.0],
        protocol: Some(Protocol {
            intervals_min: vec![1.0, 3.0, 10.0, 30.0],
            repeats: 2,
            ..Protocol::default()
        }),
        field: Some(Field {
            sessions,
            motion: Some(motion),
            ..Field::default()
        }),
        ..Campaign::default()
    }
}

/// The recordings' activations in file order, each with the rotations the simulator added.
fn read(c: &Campaign, dir: &Path) -> anyhow::Result<Vec<(Segment, Vec<Rotation>)>> {
    simulate_campaign(c, dir, |_| {})?;
    let plans: BTreeMap<String, _> = plan(c).into_iter().map(|f| (f.stem.clone(), f)).collect();
    let mut out = Vec::new();
    for path in drift_evaluate::pipeline::recording_files(dir)? {
        let stem = path
            .file_stem()
            .context("a recording without a name")?
            .to_string_lossy()
            .into_owned();
        let file = plans.get(&stem).context(format!("no plan for {stem}"))?;
        let recording = read_recording(&path)?;
        anyhow::ensure!(recording.segments.len() == file.activations.len());
        for (segment, act) in recording.segments.into_iter().zip(&file.activations) {
            out.push((segment, act.motion.clone()));
        }
    }
    Ok(out)
}

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Way {
    Tables,
    Learner,
    Both,
}

/// One field activation corrected `way`, less the true body rate: the residual per axis, °/s.
fn residual(
    way: Way,
    tables: Option<&drift_core::ModifiedTables>,
    segment: &Segment,
    rotations: &[Rotation],
    settings: &FitSettings,
) -> anyhow::Result<[Vec<f32>; 3]> {
    let mut corrector = match (way, tables) {
        (Way::Learner, _) | (_, None) => None,
        (_, Some(t)) => {
            let mut c = Corrector::new(t)?;
            c.power_on(switch_on_raw(segment, settings))
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            Some(c)
        }
    };
    let fs = segment.sample_rate_hz;
    let learner_settings = StillnessSettings {
        sample_rate_hz: fs as f32,
        ..StillnessSettings::default()
    };
    let mut learner = (way != Way::Tables)
        .then(|| StillnessLearner::new(&learner_settings))
        .transpose()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let accel = ["accel_x", "accel_y", "accel_z"].map(|n| segment.aux.get(n));
    let every = (fs / drift_recording::AUX_RATE_HZ).max(1) as usize;
    let mut out: [Vec<f32>; 3] = Default::default();
    for i in 0..segment.len() {
        let sample = sample_at(segment, i);
        let mut rate = match corrector.as_mut() {
            Some(c) => c.correct(&sample).corrected_dps,
            None => sample.rate_dps,
        };
        if let Some(learner) = learner.as_mut() {
            if i % every == 0 {
                if let [Some(x), Some(y), Some(z)] = accel {
                    let k = i / every;
                    if let (Some(&x), Some(&y), Some(&z)) =
                        (x.values.get(k), y.values.get(k), z.values.get(k))
                    {
                        learner.accelerometer([x, y, z]);
                    }
                }
            }
            rate = learner.update(rate).rate_dps;
        }
        let body = motion::true_rate(rotations, i as u32);
        for a in 0..3 {
            out[a].push((f64::from(rate[a]) - body[a]) as f32);
        }
    }
    Ok(out)
}

type Cells = BTreeMap<(String, usize, bool, Way), Vec<f64>>;

fn evaluate(
    activations: &[(Segment, Vec<Rotation>)],
    fitted: &BTreeMap<String, drift_core::ModifiedTables>,
    settings: &FitSettings,
    ways: &[Way],
) -> anyhow::Result<Cells> {
    let mut cells = Cells::new();
    for (segment, rotations) in activations {
        if segment.labels.series_kind != SeriesKind::Field {
            continue;
        }
        let unit = &segment.labels.unit_id;
        let warm = segment
            .labels
            .off_before_s
            .is_some_and(|s| s < settings.independent_after_min * 60.0);
        for &way in ways {
            let r = residual(way, fitted.get(unit), segment, rotations, settings)?;
            let (_, rms) = metric(&r, settings.lowpass_window(segment.sample_rate_hz));
            for (axis, rms) in rms.iter().enumerate() {
                cells
                    .entry((unit.clone(), axis, warm, way))
                    .or_default()
                    .push(*rms);
            }
        }
    }
    Ok(cells)
}

/// The noise floor per unit × axis × class: the zero-drift twin's rate less the body rate and less
/// the unit's constant bias (its mean over every field activation), as
/// `drift_evaluate::evaluate::noise_floor` takes it for static units. The turn-on jitter stays in:
/// tables cannot know it, a learner can.
fn floor(twin: &[(Segment, Vec<Rotation>)], settings: &FitSettings) -> anyhow::Result<Cells> {
    let field: Vec<_> = twin
        .iter()
        .filter(|(s, _)| s.labels.series_kind == SeriesKind::Field)
        .collect();
    let mut residuals = Vec::new();
    let mut sums: BTreeMap<String, ([f64; 3], usize)> = BTreeMap::new();
    for (segment, rotations) in field {
        let r = residual(Way::Tables, None, segment, rotations, settings)?;
        let sum = sums.entry(segment.labels.unit_id.clone()).or_default();
        for (total, axis) in sum.0.iter_mut().zip(&r) {
            *total += axis.iter().map(|&v| f64::from(v)).sum::<f64>() / axis.len().max(1) as f64;
        }
        sum.1 += 1;
        residuals.push((segment, r));
    }
    let mut cells = Cells::new();
    for (segment, r) in residuals {
        let unit = &segment.labels.unit_id;
        let (sum, n) = sums[unit];
        let centred: [Vec<f32>; 3] = std::array::from_fn(|a| {
            r[a].iter()
                .map(|&v| (f64::from(v) - sum[a] / n as f64) as f32)
                .collect()
        });
        let (_, rms) = metric(&centred, settings.lowpass_window(segment.sample_rate_hz));
        let warm = segment
            .labels
            .off_before_s
            .is_some_and(|s| s < settings.independent_after_min * 60.0);
        for (axis, rms) in rms.iter().enumerate() {
            cells
                .entry((unit.clone(), axis, warm, Way::Tables))
                .or_default()
                .push(*rms);
        }
    }
    Ok(cells)
}

/// One unit × axis × class cell: the mean residual bias RMS over its activations, °/s.
#[derive(Serialize)]
struct Cell {
    unit: String,
    axis: usize,
    activations: usize,
    tables: f64,
    learner: f64,
    both: f64,
    floor: f64,
}

/// One class of one motion case: its cells, their means and the count against the floor.
#[derive(Serialize)]
struct Class {
    class: &'static str,
    cells: Vec<Cell>,
    tables: f64,
    learner: f64,
    both: f64,
    floor: f64,
    /// Cells where both together leave less than either alone.
    both_below_either: usize,
    /// Cells where both together leave no more than the tables alone.
    both_no_worse_than_tables: usize,
    /// With still gaps: `both_below_either` in at least 90 % of the cells; without:
    /// `both_no_worse_than_tables` in every cell.
    floor_met: bool,
}

#[derive(Serialize)]
struct Case {
    motion: &'static str,
    still_gaps: bool,
    classes: Vec<Class>,
}

fn summarise(motion: &'static str, gaps: bool, cells: &Cells, floor: &Cells) -> Case {
    let mut classes = Vec::new();
    for warm in [false, true] {
        let keys: Vec<(String, usize)> = cells
            .keys()
            .filter(|k| k.2 == warm && k.3 == Way::Tables)
            .map(|k| (k.0.clone(), k.1))
            .collect();
        if keys.is_empty() {
            continue;
        }
        let get = |k: &(String, usize), way| {
            cells
                .get(&(k.0.clone(), k.1, warm, way))
                .map_or(f64::NAN, |v| mean(v))
        };
        let cells: Vec<Cell> = keys
            .iter()
            .map(|k| Cell {
                unit: k.0.clone(),
                axis: k.1,
                activations: cells
                    .get(&(k.0.clone(), k.1, warm, Way::Tables))
                    .map_or(0, Vec::len),
                tables: get(k, Way::Tables),
                learner: get(k, Way::Learner),
                both: get(k, Way::Both),
                floor: floor
                    .get(&(k.0.clone(), k.1, warm, Way::Tables))
                    .map_or(f64::NAN, |v| mean(v)),
            })
            .collect();
        let column = |f: fn(&Cell) -> f64| mean(&cells.iter().map(f).collect::<Vec<_>>());
        let both_below_either = cells
            .iter()
            .filter(|c| c.both < c.tables.min(c.learner))
            .count();
        let both_no_worse_than_tables = cells.iter().filter(|c| c.both <= c.tables).count();
        let floor_met = if gaps {
            both_below_either as f64 >= FLOOR_SHARE_WITH_GAPS * cells.len() as f64
        } else {
            both_no_worse_than_tables == cells.len()
        };
        classes.push(Class {
            class: if warm { "warm restart" } else { "cold start" },
            tables: column(|c| c.tables),
            learner: column(|c| c.learner),
            both: column(|c| c.both),
            floor: column(|c| c.floor),
            both_below_either,
            both_no_worse_than_tables,
            floor_met,
            cells,
        });
    }
    Case {
        motion,
        still_gaps: gaps,
        classes,
    }
}

fn print_case(case: &Case) {
    println!(
        "\n{}: residual bias RMS, °/s, mean over cells (unit × axis)\n",
        case.motion
    );
    println!("| class | cells | activations per cell | tables | learner | both | floor | cells where both < min(tables, learner) | cells where both ≤ tables | floor met |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for c in &case.classes {
        let n = c.cells.len();
        let share = |k: usize| 100.0 * k as f64 / n as f64;
        println!(
            "| {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {} ({:.0} %) | {} ({:.0} %) | {} |",
            c.class,
            n,
            c.cells.first().map_or(0, |x| x.activations),
            c.tables,
            c.learner,
            c.both,
            c.floor,
            c.both_below_either,
            share(c.both_below_either),
            c.both_no_worse_than_tables,
            share(c.both_no_worse_than_tables),
            if c.floor_met { "yes" } else { "no" },
        );
    }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn main() -> anyhow::Result<()> {
    let Args {
        seed,
        units,
        sessions,
        json,
    } = clap::Parser::parse();
    let settings = FitSettings::default();
    let work = tempfile::tempdir()?;
    let ways = [Way::Tables, Way::Learner, Way::Both];

    let gaps = campaign(seed, units, sessions, UnitModel::Physical, true);
    let with_gaps = read(&gaps, &work.path().join("gaps"))?;
    let mut fitted = BTreeMap::new();
    let mut by_unit: BTreeMap<String, Vec<&Segment>> = BTreeMap::new();
    for (segment, _) in &with_gaps {
        let calibration = segment.labels.series_kind == SeriesKind::Protocol
            && CALIBRATION
                .iter()
                .any(|sp| (segment.labels.nominal_set_point_celsius() - sp).abs() < 1e-9);
        if calibration {
            by_unit
                .entry(segment.labels.unit_id.clone())
                .or_default()
                .push(segment);
        }
    }
    for (unit, segments) in by_unit {
        let analysed = segments
            .iter()
            .map(|s| analyse(s, &settings))
            .collect::<Result<Vec<_>, _>>()?;
        fitted.insert(unit, fit_unit(&analysed, &settings)?.modified);
    }
    let cells_gaps = evaluate(&with_gaps, &fitted, &settings, &ways)?;
    drop(with_gaps);
    let no_gaps = read(
        &campaign(seed, units, sessions, UnitModel::Physical, false),
        &work.path().join("no-gaps"),
    )?;
    let cells_none = evaluate(&no_gaps, &fitted, &settings, &ways)?;
    drop(no_gaps);
    // The floor: a zero-drift twin moving the same way, the learner after nothing to remove.
    let twin = read(
        &campaign(seed, units, sessions, UnitModel::ZeroSystematicDrift, true),
        &work.path().join("twin"),
    )?;
    let floor = floor(&twin, &settings)?;

    let cases = [
        summarise("rotations with still gaps", true, &cells_gaps, &floor),
        summarise("rotations without still gaps", false, &cells_none, &floor),
    ];
    for case in &cases {
        print_case(case);
    }
    if let Some(path) = json {
        let out = serde_json::json!({
            "seed": seed,
            "units": units,
            "sessions": sessions,
            "floor_share_with_gaps": FLOOR_SHARE_WITH_GAPS,
            "cases": cases,
        });
        std::fs::write(&path, serde_json::to_string_pretty(&out)?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}
