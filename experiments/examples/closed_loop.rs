//! The closed-loop experiment (tables in experiments/README.md) ([`experiments::closed_loop`]): one table row
//! per effect, seed and axis, printed as each run ends, then the null case's and each effect's
//! summary.
//!
//! ```sh
//! cargo run --release -p experiments --example closed_loop -- [--seeds 1] [--first-seed 1] [--sessions 6] \
//!     [--scale 1] [--effects thermal_lag,supply_voltage] [--calibration 30,40] \
//!     [--unit physical|paper_exact]
//! ```
//!
//! `--calibration` sets the calibration set points (°C, increasing; +33 °C is the validation set
//! point and cannot be one); the protocol and field sessions are recorded at each. `--intervals`
//! sets the calibration protocol's off-times (min, increasing; default 1,2,5,10,30).
//! `--per-activation yes` prints each held-out +33 °C field activation's offset and drift before
//! and after; `--profile yes` where within the activations the loop's residual sits, by time since
//! switch-on and off-time before. `--unit paper_exact` simulates a unit the paper's model
//! represents exactly (its bias follows the sensor's temperature linearly): with `--effects none`
//! the null case for the diagnosis's false-alarm rate, which the physical unit's element lag is not.

use anyhow::Context;
use drift_sim::UnitModel;
use experiments::closed_loop::{run, Plan, Row};

const EFFECTS: [&str; 8] = [
    "none",
    "thermal_lag",
    "acceleration",
    "supply_voltage",
    "cross_axis",
    "rise_nonlinearity",
    "ageing",
    "ambient_ramp",
];

fn print(r: &Row) {
    println!(
        "| {} | {} | {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {} | {:.4} | {:.4} | {:.4} | {} | {:.4} | {} | {} |",
        r.effect,
        r.seed,
        r.axis,
        r.paper_top,
        r.top,
        if r.significant { "yes" } else { "no" },
        r.terms(),
        r.before.1,
        r.after.1,
        r.floor.1,
        cut(r.before.1, r.after.1, r.floor.1, r.excess_cut()),
        r.before.0,
        r.after.0,
        r.floor.0,
        cut(r.before.0, r.after.0, r.floor.0, r.drift_cut()),
        r.by_history.0,
        cut(r.before.0, r.by_history.0, r.floor.0, r.history_drift_cut()),
        r.drift_cut_interval.interval_text(),
    );
}

/// An excess cut for the table: a model that ends within the table's last digit (0.00005 °/s) of
/// the floor has nothing left to cut, and the ratio would only measure that digit.
fn cut(before: f64, after: f64, floor: f64, ratio: f64) -> String {
    if before <= floor {
        "– (floor above)".to_owned()
    } else if after - floor < 0.00005 {
        "at the floor".to_owned()
    } else {
        format!("{ratio:.1}×")
    }
}

const USAGE: &str = "closed_loop [--seeds 1] [--first-seed 1] [--sessions 6] [--scale 1] \
[--effects none,thermal_lag,…] [--calibration 30,40] [--intervals 1,2,5,10,30] [--clock yes|no] \
[--per-activation no|yes] [--profile no|yes] [--unit physical|paper_exact]";
const FLAGS: [&str; 11] = [
    "--seeds",
    "--first-seed",
    "--sessions",
    "--scale",
    "--effects",
    "--calibration",
    "--intervals",
    "--clock",
    "--per-activation",
    "--profile",
    "--unit",
];

/// `text` read as a number; the error names the flag (a bare "invalid float literal" does not say
/// which of two lists).
fn parsed<T: std::str::FromStr>(flag: &str, text: &str) -> anyhow::Result<T>
where
    T::Err: std::error::Error + Send + Sync + 'static,
{
    text.trim()
        .parse()
        .with_context(|| format!("{flag}: cannot read `{}`", text.trim()))
}

/// The number after `flag`, or `default` without one.
fn number<T: std::str::FromStr>(
    value: &dyn Fn(&str) -> Option<String>,
    flag: &str,
    default: T,
) -> anyhow::Result<T>
where
    T::Err: std::error::Error + Send + Sync + 'static,
{
    value(flag).map_or(Ok(default), |s| parsed(flag, &s))
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--help" || a == "-h") {
        println!("{USAGE}\neffects: {}", EFFECTS.join(", "));
        return Ok(());
    }
    // A mistyped flag would otherwise run the whole experiment with a default in its place.
    for pair in args.chunks(2) {
        anyhow::ensure!(
            FLAGS.contains(&pair[0].as_str()) && pair.len() == 2,
            "`{}` is not a flag with a value; usage: {USAGE}",
            pair[0]
        );
    }
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let yes_no = |flag: &str, default: bool| -> anyhow::Result<bool> {
        match value(flag).as_deref() {
            None => Ok(default),
            Some("yes") => Ok(true),
            Some("no") => Ok(false),
            Some(other) => anyhow::bail!("{flag} takes yes or no, got `{other}`"),
        }
    };
    let list = |flag: &str, default: Vec<f64>| {
        value(flag).map_or(Ok(default), |s| {
            s.split(',').map(|t| parsed::<f64>(flag, t)).collect()
        })
    };
    let seeds: u64 = number(&value, "--seeds", 1)?;
    let first_seed: u64 = number(&value, "--first-seed", 1)?;
    let defaults = Plan::default();
    let plan = Plan {
        sessions: number(&value, "--sessions", defaults.sessions)?,
        scale: number(&value, "--scale", defaults.scale)?,
        calibration: list("--calibration", defaults.calibration)?,
        clock: yes_no("--clock", true)?,
        per_activation: yes_no("--per-activation", false)?,
        profile: yes_no("--profile", false)?,
        intervals_min: list("--intervals", defaults.intervals_min)?,
        unit: match value("--unit").as_deref() {
            None | Some("physical") => UnitModel::Physical,
            Some("paper_exact") => UnitModel::PaperExact,
            Some(other) => anyhow::bail!("--unit takes physical or paper_exact, got `{other}`"),
        },
    };
    plan.check()?;
    eprintln!(
        "{:?} unit; calibration set points {:?} °C, off-times {:?} min; history-keyed firmware {} a clock",
        plan.unit,
        plan.calibration,
        plan.intervals_min,
        if plan.clock { "with" } else { "without" }
    );
    let effects: Vec<String> = value("--effects").map_or_else(
        || EFFECTS.map(String::from).to_vec(),
        |s| s.split(',').map(String::from).collect(),
    );
    let work = tempfile::tempdir()?;
    let settings = drift_fit::FitSettings::default();
    let mut rows: Vec<Row> = Vec::new();
    println!("| effect | seed | axis | top candidate behind the paper's model | top candidate left behind the loop's model | significant | terms admitted | RMS before | RMS after | noise floor RMS | excess cut | drift before | drift after | noise floor drift | drift excess cut | drift keyed by history | drift excess cut by history | drift excess cut, 95 % interval |");
    println!(
        "|---|---:|---|---|---|:---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for effect in &effects {
        for seed in first_seed..first_seed + seeds {
            eprintln!("{effect}, seed {seed} …");
            // Printed as each run ends: a long experiment keeps what it has measured.
            for r in run(effect, seed, work.path(), &settings, &plan)? {
                print(&r);
                rows.push(r);
            }
        }
    }
    println!();
    for effect in &effects {
        let of: Vec<&Row> = rows.iter().filter(|r| &r.effect == effect).collect();
        let share = |f: &dyn Fn(&Row) -> bool| {
            let n = of.iter().filter(|r| f(r)).count();
            format!(
                "{n} of {} ({:.0} %)",
                of.len(),
                100.0 * n as f64 / of.len().max(1) as f64
            )
        };
        println!(
            "{effect}: diagnosis significant on {}; a term admitted on {}; drift excess cut ≥ 2× on {}, below 2× with 95 % confidence on {} (RMS excess cut ≥ 2× on {}); stage 3 keyed by history chosen on {}; warm starts' initial bias chosen on {}; {:?} unit, scale {}, calibration at {:?} °C, {} field activations measured and {} trained on per run",
            share(&|r| r.significant),
            share(&|r| !r.admitted.is_empty()),
            // To the table's rounding: 1.95× prints as 2.0×. A model that ends at the floor
            // has cut all there was (before above the floor).
            share(&|r| r.before.0 > r.floor.0 && r.drift_cut() >= 1.95),
            share(&|r| r.before.0 > r.floor.0 && r.drift_cut_interval.surely_below(2.0)),
            share(&|r| r.before.1 > r.floor.1 && r.excess_cut() >= 1.95),
            share(&|r| r.history_chosen),
            share(&|r| r.warm_start_chosen),
            plan.unit,
            plan.scale,
            plan.calibration,
            of.first().map_or(0, |r| r.field_activations),
            of.first().map_or(0, |r| r.training_activations),
        );
    }
    Ok(())
}
