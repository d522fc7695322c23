//! The closed loop on worlds it was not built with ([`experiments::worlds`]; the table is in
//! experiments/README.md, *worlds*): per effect family, worlds drawn with only that family; null
//! worlds; the loop run blind on each; scored against the truth afterwards.
//!
//! ```sh
//! cargo run --release -p experiments --example worlds -- [--families all|humidity,…] \
//!     [--worlds-per-family 20] [--null-worlds 30] [--first-seed 10000] [--jobs 1] \
//!     [--out table.md] [--json scores.jsonl] [--small] [--select-on-validation] \
//!     [--diagnosis-series 20] [--magnitude 1]
//! ```
//!
//! `--magnitude m` draws every effect at m × its realistic size (the detection curve). Each
//! effect world's oracle (`experiments::oracle`: the true regressor scored by the same diagnosis)
//! runs in a third child after the blind loop.
//!
//! `--diagnosis-series N` records, per world, an analyst's diagnosis campaign beside the
//! calibration one (N ramped field series of 5 at +33 °C) and diagnoses on it, cross-fitted by
//! series.
//!
//! World k of every family (and null world k) is drawn from seed `first-seed + k`: the same unit
//! and structure, different effects. Each world is recorded in a child process, its loop run in
//! another (which sees only the two recordings folders), so that each reports its own wall time
//! and peak memory; the parent then reads the truth, scores, and deletes the world's files.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

use anyhow::Context;
use drift_sim::world::effects::EffectFamily;
use experiments::oracle::{close_oracle, OracleOutcome};
use experiments::worlds::{
    close_blind, fit_settings, record, score, table, world_lines, Failure, Kind, Outcome, Recorded,
    WorldPaths, WorldScore, DEFAULT_FIRST_SEED,
};

const USAGE: &str = "worlds [--families all|accelerometer,humidity,…] [--worlds-per-family 20] \
[--null-worlds 30] [--first-seed 10000] [--jobs 1] [--out table.md] [--json scores.jsonl] [--small] \
[--select-on-validation] [--diagnosis-series 20] [--magnitude 1]";

/// The value after `flag`.
fn value(args: &[String], flag: &str) -> Option<String> {
    args.iter()
        .position(|a| a == flag)
        .and_then(|i| args.get(i + 1).cloned())
}

fn number<T: std::str::FromStr>(args: &[String], flag: &str, default: T) -> anyhow::Result<T>
where
    T::Err: std::error::Error + Send + Sync + 'static,
{
    value(args, flag).map_or(Ok(default), |s| {
        s.parse()
            .with_context(|| format!("{flag}: cannot read `{s}`"))
    })
}

/// Stack of a child's worker thread, bytes (reserved address space, not memory in use).
const CHILD_STACK_BYTES: usize = 256 << 20;

/// The last line of a child's standard output, as JSON.
fn child<T: serde::de::DeserializeOwned>(args: &[&str]) -> anyhow::Result<T> {
    let out = Command::new(std::env::current_exe()?)
        .args(args)
        .output()
        .context("starting a child process")?;
    anyhow::ensure!(
        out.status.success(),
        "child {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr).trim()
    );
    let text = String::from_utf8(out.stdout)?;
    let line = text.lines().last().context("child printed nothing")?;
    Ok(serde_json::from_str(line)?)
}

/// One world: recorded in one child, closed blind in another, scored here.
fn one_world(
    kind: Kind,
    seed: u64,
    work: &Path,
    small: bool,
    select: bool,
    diagnosis_series: u32,
    magnitude: f64,
) -> anyhow::Result<WorldScore> {
    let paths = WorldPaths::new(work, kind, seed);
    let small_flag = if small { "yes" } else { "no" };
    let select_flag = if select { "yes" } else { "no" };
    let seed_text = seed.to_string();
    let work_text = work.display().to_string();
    let series_text = diagnosis_series.to_string();
    let magnitude_text = magnitude.to_string();
    let recorded: anyhow::Result<Recorded> = child(&[
        "--child-record",
        kind.name(),
        &seed_text,
        &work_text,
        small_flag,
        &series_text,
        &magnitude_text,
    ]);
    let diagnosis_text = if diagnosis_series > 0 {
        paths.diagnosis_dir.display().to_string()
    } else {
        "-".to_owned()
    };
    let outcome: anyhow::Result<Outcome> = match &recorded {
        Ok(_) => child(&[
            "--child-loop",
            &paths.dir.display().to_string(),
            &paths.floor_dir.display().to_string(),
            small_flag,
            select_flag,
            &diagnosis_text,
        ]),
        Err(_) => Err(anyhow::anyhow!("not recorded")),
    };
    let oracle: anyhow::Result<Option<OracleOutcome>> = match &outcome {
        Ok(_) if kind.has_oracle() => child(&[
            "--child-oracle",
            &paths.dir.display().to_string(),
            &diagnosis_text,
            &paths.oracle_dir.display().to_string(),
            &paths.floor_dir.display().to_string(),
            select_flag,
        ])
        .map(Some),
        _ => Ok(None),
    };
    paths.remove_recordings();
    let result = match (recorded, outcome, oracle) {
        (Ok(r), Ok(o), Ok(x)) => score(kind, seed, &paths.truth, &r, &o, x.as_ref()),
        (Err(e), _, _) | (_, Err(e), _) | (_, _, Err(e)) => Err(e),
    };
    paths.remove_truth();
    result
}

/// A child's part: `--child-record <kind> <seed> <work> <small: yes|no> <diagnosis series>`
/// records one world; `--child-loop <world dir> <floor dir> <small: yes|no> <select on +33 °C:
/// yes|no> <diagnosis dir or ->` closes the loop on the recordings folders; `--child-oracle
/// <world dir> <diagnosis dir or -> <oracle dir> <floor dir> <select: yes|no>` closes it again
/// with the true regressor among the candidates.
fn child_part(args: &[String]) -> anyhow::Result<()> {
    let small = |i: usize| args.get(i).is_some_and(|s| s == "yes");
    let arg = |i: usize| args.get(i).context("missing a child argument");
    let line = if args[0] == "--child-record" {
        let kind = Kind::parse(arg(1)?)?;
        let seed: u64 = arg(2)?.parse()?;
        let paths = WorldPaths::new(Path::new(arg(3)?), kind, seed);
        let series: u32 = arg(5)?.parse()?;
        let magnitude: f64 = arg(6)?.parse()?;
        serde_json::to_string(&record(kind, seed, &paths, small(4), series, magnitude)?)?
    } else if args[0] == "--child-oracle" {
        let diagnosis = arg(2)?;
        serde_json::to_string(&close_oracle(
            Path::new(arg(1)?),
            (diagnosis != "-").then(|| Path::new(diagnosis)),
            Path::new(arg(3)?),
            Path::new(arg(4)?),
            &fit_settings(),
            small(5),
        )?)?
    } else {
        // Sees the two recordings folders and nothing else.
        let settings = fit_settings();
        let diagnosis = arg(5)?;
        serde_json::to_string(&close_blind(
            Path::new(arg(1)?),
            Path::new(arg(2)?),
            &settings,
            small(4),
            (diagnosis != "-").then(|| Path::new(diagnosis)),
        )?)?
    };
    println!("{line}");
    Ok(())
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args
        .first()
        .is_some_and(|a| a == "--child-record" || a == "--child-loop" || a == "--child-oracle")
    {
        // The loop's tables live on the stack as in the command line's worker (src/main.rs):
        // the main thread's 8 MiB overflowed on some worlds.
        return std::thread::Builder::new()
            .name("worlds-child".into())
            .stack_size(CHILD_STACK_BYTES)
            .spawn(move || child_part(&args))?
            .join()
            .unwrap_or_else(|_| Err(anyhow::anyhow!("the child's work panicked")));
    }
    if args.iter().any(|a| a == "--help" || a == "-h") {
        let names: Vec<&str> = EffectFamily::ALL.iter().map(|f| f.name()).collect();
        println!("{USAGE}\nfamilies: {}", names.join(", "));
        return Ok(());
    }
    let small = args.iter().any(|a| a == "--small");
    // The +33 °C protocol activations join the diagnosis (not the measurement).
    let select = args.iter().any(|a| a == "--select-on-validation");
    let rest: Vec<&String> = args
        .iter()
        .filter(|a| *a != "--small" && *a != "--select-on-validation")
        .collect();
    const FLAGS: [&str; 9] = [
        "--magnitude",
        "--diagnosis-series",
        "--families",
        "--worlds-per-family",
        "--null-worlds",
        "--first-seed",
        "--jobs",
        "--out",
        "--json",
    ];
    for pair in rest.chunks(2) {
        anyhow::ensure!(
            FLAGS.contains(&pair[0].as_str()) && pair.len() == 2,
            "`{}` is not a flag with a value; usage: {USAGE}",
            pair[0]
        );
    }
    let families: Vec<EffectFamily> = match value(&args, "--families").as_deref() {
        None | Some("all") => EffectFamily::ALL.to_vec(),
        Some(list) => list
            .split(',')
            .map(|t| match Kind::parse(t)? {
                Kind::Effect(f) => Ok(f),
                Kind::Null => anyhow::bail!("null worlds are --null-worlds"),
            })
            .collect::<anyhow::Result<_>>()?,
    };
    let per_family: u64 = number(&args, "--worlds-per-family", 20)?;
    let nulls: u64 = number(&args, "--null-worlds", 30)?;
    let first: u64 = number(&args, "--first-seed", DEFAULT_FIRST_SEED)?;
    let jobs: usize = number(&args, "--jobs", 1usize)?.max(1);
    let diagnosis_series: u32 = number(&args, "--diagnosis-series", 0)?;
    let magnitude: f64 = number(&args, "--magnitude", 1.0)?;
    anyhow::ensure!(
        magnitude.is_finite() && magnitude > 0.0,
        "--magnitude: {magnitude} is not a positive size"
    );
    let out: Option<PathBuf> = value(&args, "--out").map(PathBuf::from);
    // Every world's score with its whole ranking, one JSON line each: what the significance
    // threshold is calibrated from (experiments/null_threshold.py).
    let json: Option<PathBuf> = value(&args, "--json").map(PathBuf::from);
    if let Some(path) = &json {
        // Lines are appended world by world (below): start the file empty.
        std::fs::write(path, "").with_context(|| format!("writing {}", path.display()))?;
    }

    let mut kinds: Vec<Kind> = families.iter().map(|&f| Kind::Effect(f)).collect();
    if nulls > 0 {
        kinds.push(Kind::Null);
    }
    // World k of every kind before world k + 1 of any: a run cut short has every row.
    let count = |kind: Kind| {
        if kind == Kind::Null {
            nulls
        } else {
            per_family
        }
    };
    let max = per_family.max(nulls);
    let queue: Vec<(Kind, u64)> = (0..max)
        .flat_map(|k| {
            kinds
                .iter()
                .filter(move |&&kind| k < count(kind))
                .map(move |&kind| (kind, first + k))
        })
        .collect();
    let command = format!(
        "cargo run --release -p experiments --example worlds -- {}",
        args.join(" ")
    );
    eprintln!(
        "{} worlds ({} campaign), seeds from {first}, {jobs} at a time",
        queue.len(),
        if small { "small" } else { "full" }
    );
    let work = tempfile::Builder::new()
        .prefix("gyrodrift-worlds-")
        .tempdir()?;
    let queue = Mutex::new(queue.into_iter());
    let results: Mutex<(Vec<WorldScore>, Vec<Failure>)> = Mutex::new((Vec::new(), Vec::new()));
    let started = std::time::Instant::now();
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let next = queue.lock().map(|mut q| q.next()).ok().flatten();
                let Some((kind, seed)) = next else { break };
                let result = one_world(
                    kind,
                    seed,
                    work.path(),
                    small,
                    select,
                    diagnosis_series,
                    magnitude,
                );
                let mut guard = match results.lock() {
                    Ok(g) => g,
                    Err(p) => p.into_inner(),
                };
                match result {
                    Ok(score) => {
                        // Each world's line as soon as it is scored: a long run stopped early
                        // keeps what it measured.
                        if let Some(path) = &json {
                            let line = serde_json::to_string(&score).unwrap_or_default();
                            let appended = std::fs::OpenOptions::new()
                                .create(true)
                                .append(true)
                                .open(path)
                                .and_then(|mut f| {
                                    std::io::Write::write_all(&mut f, (line + "\n").as_bytes())
                                });
                            if let Err(e) = appended {
                                eprintln!("writing {}: {e}", path.display());
                            }
                        }
                        for line in world_lines(&score) {
                            eprintln!("{line}");
                        }
                        eprintln!(
                            "  {} {}: record {:.1} s ({:.0} MB), loop {:.1} s ({:.0} MB)",
                            score.kind,
                            score.seed,
                            score.record_seconds,
                            score.record_peak_rss_mb,
                            score.loop_seconds,
                            score.loop_peak_rss_mb
                        );
                        guard.0.push(score);
                    }
                    Err(e) => {
                        eprintln!("{} {seed}: failed: {e:#}", kind.name());
                        guard.1.push(Failure {
                            kind: kind.name(),
                            seed,
                            error: format!("{e:#}"),
                        });
                    }
                }
            });
        }
    });
    let (mut scores, failures) = results.into_inner().unwrap_or_else(|p| p.into_inner());
    scores.sort_by_key(|s| (s.kind, s.seed));
    let text = format!(
        "```sh\n{command}\n```\n\n{} worlds scored, {} failed, seeds {first}–{}; {:.0} s in all ({jobs} at a time).\n\n{}",
        scores.len(),
        failures.len(),
        first + max.saturating_sub(1),
        started.elapsed().as_secs_f64(),
        table(&scores, &failures, &kinds)
    );
    println!("{text}");
    for f in &failures {
        println!("- failed: {} seed {}: {}", f.kind, f.seed, f.error);
    }
    if let Some(path) = out {
        let mut body = text;
        for f in &failures {
            body += &format!("- failed: {} seed {}: {}\n", f.kind, f.seed, f.error);
        }
        body += "\nPer world and axis:\n\n```text\n";
        for s in &scores {
            for line in world_lines(s) {
                body += &line;
                body.push('\n');
            }
        }
        body += "```\n";
        std::fs::write(&path, body).with_context(|| format!("writing {}", path.display()))?;
        eprintln!("table written to {}", path.display());
    }
    Ok(())
}
