//! `gyrodrift.simulate` and `gyrodrift.resolve_campaign`: a campaign from a dict, TOML/JSON text or
//! a file, with keyword overrides that mean what `gyrodrift simulate`'s flags mean, simulated by
//! drift-sim into a folder (same campaign and seed → the same bytes as the command line).

use std::path::{Path, PathBuf};

use drift_sim::campaign::{set_point_range, TruthBias};
use drift_sim::{Campaign, Field, Protocol, UnitModel};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::args;
use crate::arrays::describe;
use crate::errors::Error;

/// The keyword overrides, one per flag of `gyrodrift simulate`.
#[derive(Debug, Default)]
struct Overrides {
    seed: Option<u64>,
    units: Option<u32>,
    set_points: Option<Vec<f64>>,
    intervals: Option<Vec<f64>>,
    repeats: Option<u32>,
    field: bool,
    field_only: bool,
    zero_drift: bool,
    paper_exact: bool,
    effects: Vec<String>,
    noise_scale: Option<f64>,
    truth_at_aux_rate: bool,
}

/// `--set-points`: a list of floats, or the flag's text (`"30,40,33"` or `"-40:60:10"`).
fn set_points(value: &Bound<'_, PyAny>) -> Result<Vec<f64>, Error> {
    const EXPECTED: &str =
        "a sequence of floats (°C) or text as the --set-points flag takes (\"30,40,33\" or \"-40:60:10\")";
    let bad = || {
        Error::Input(format!(
            "`set_points` must be {EXPECTED}, got {}",
            args::shown(value)
        ))
    };
    if let Ok(text) = value.cast::<PyString>() {
        let text = text.to_string();
        let number = |s: &str| s.trim().parse::<f64>().map_err(|_| bad());
        if text.contains(':') {
            let parts: Vec<&str> = text.split(':').collect();
            let [from, to, step] = parts.as_slice() else {
                return Err(bad());
            };
            let points = set_point_range(number(from)?, number(to)?, number(step)?);
            if points.is_empty() {
                return Err(Error::Input(format!(
                    "`set_points` range {text:?} is empty"
                )));
            }
            return Ok(points);
        }
        return text.split(',').map(number).collect();
    }
    args::value("set_points", EXPECTED, value)
}

impl Overrides {
    /// Applies the overrides as `gyrodrift simulate` applies its flags (src/cli/simulate.rs).
    fn apply(&self, mut c: Campaign) -> Result<Campaign, Error> {
        if let Some(seed) = self.seed {
            c.seed = seed;
        }
        if let Some(units) = self.units {
            c.units = units;
        }
        if let Some(points) = &self.set_points {
            c.set_points_celsius.clone_from(points);
        }
        if self.intervals.is_some() || self.repeats.is_some() {
            let p = c.protocol.get_or_insert_with(Protocol::default);
            if let Some(intervals) = &self.intervals {
                p.intervals_min.clone_from(intervals);
            }
            if let Some(repeats) = self.repeats {
                p.repeats = repeats;
            }
        }
        if self.field && self.field_only {
            return Err(Error::Input(
                "`field` and `field_only` cannot both be set".into(),
            ));
        }
        if self.field || self.field_only {
            c.field.get_or_insert_with(Field::default);
        }
        if self.field_only {
            c.protocol = None;
        }
        if self.zero_drift && self.paper_exact {
            return Err(Error::Input(
                "`zero_drift` and `paper_exact` cannot both be set".into(),
            ));
        }
        if self.zero_drift {
            c.unit_model = UnitModel::ZeroSystematicDrift;
        }
        if self.paper_exact {
            c.unit_model = UnitModel::PaperExact;
        }
        for name in &self.effects {
            c.effects
                .enable(name.trim())
                .map_err(|reason| Error::Input(format!("`effects`: {reason}")))?;
        }
        if self.truth_at_aux_rate {
            c.truth_bias = TruthBias::AuxRate;
        }
        if let Some(scale) = self.noise_scale {
            c.noise_scale = scale;
        }
        c.validate()?;
        Ok(c)
    }
}

/// Text as TOML, or as JSON when it starts with `{`.
fn parse_text(text: &str) -> Result<Campaign, Error> {
    let trimmed = text.trim_start();
    let parsed = if trimmed.starts_with('{') {
        serde_json::from_str(text).map_err(|e| format!("not a valid campaign JSON: {e}"))
    } else {
        toml::from_str(text).map_err(|e| format!("not a valid campaign TOML: {e}"))
    };
    parsed.map_err(|mut message| {
        if !text.contains('\n') && Path::new(text).is_file() {
            message.push_str(" (to read the file, pass a pathlib.Path)");
        }
        Error::Campaign(message)
    })
}

/// The base campaign: the paper's, a dict, TOML/JSON text, or a file (`os.PathLike`).
fn base(py: Python<'_>, campaign: Option<&Bound<'_, PyAny>>) -> Result<Campaign, Error> {
    let Some(value) = campaign.filter(|c| !c.is_none()) else {
        return Ok(Campaign::default());
    };
    let mut c = if let Ok(text) = value.cast::<PyString>() {
        parse_text(&text.to_string())?
    } else if value.cast::<PyDict>().is_ok() {
        let json = py
            .import("json")
            .and_then(|json| json.call_method1("dumps", (value,)))
            .and_then(|text| text.extract::<String>())
            .map_err(|e| Error::Campaign(format!("campaign dict is not JSON-serialisable: {e}")))?;
        serde_json::from_str(&json)
            .map_err(|e| Error::Campaign(format!("not a valid campaign: {e}")))?
    } else if let Ok(path) = value.extract::<PathBuf>() {
        // The command line's reader: JSON for `.json`, TOML otherwise; it also validates.
        return Ok(Campaign::from_file(&path)?);
    } else {
        return Err(Error::Input(format!(
            "`campaign` must be None, a dict, TOML/JSON text or a path (os.PathLike), got {}",
            describe(value)
        )));
    };
    if c.protocol.is_none() && c.field.is_none() {
        c.protocol = Some(Protocol::default());
    }
    Ok(c)
}

/// Resolves the campaign and the overrides into a validated `Campaign`.
#[allow(clippy::too_many_arguments)]
fn resolve(
    py: Python<'_>,
    campaign: Option<&Bound<'_, PyAny>>,
    seed: Option<&Bound<'_, PyAny>>,
    units: Option<&Bound<'_, PyAny>>,
    set_points_value: Option<&Bound<'_, PyAny>>,
    intervals: Option<&Bound<'_, PyAny>>,
    repeats: Option<&Bound<'_, PyAny>>,
    field: bool,
    field_only: bool,
    zero_drift: bool,
    paper_exact: bool,
    effects: Option<&Bound<'_, PyAny>>,
    noise_scale: Option<&Bound<'_, PyAny>>,
    truth_at_aux_rate: bool,
) -> Result<Campaign, Error> {
    let overrides = Overrides {
        seed: args::optional("seed", "an integer in 0..=2**64-1", seed)?,
        units: args::optional("units", "an integer ≥ 1", units)?,
        set_points: set_points_value
            .filter(|v| !v.is_none())
            .map(set_points)
            .transpose()?,
        intervals: args::optional(
            "intervals",
            "a sequence of off-times in minutes (floats)",
            intervals,
        )?,
        repeats: args::optional("repeats", "an integer ≥ 1", repeats)?,
        field,
        field_only,
        zero_drift,
        paper_exact,
        effects: args::optional("effects", "a sequence of effect names (str)", effects)?
            .unwrap_or_default(),
        noise_scale: args::optional("noise_scale", "a float ≥ 0", noise_scale)?,
        truth_at_aux_rate,
    };
    if let Some(effects) = effects.filter(|e| e.is_instance_of::<PyString>()) {
        return Err(Error::Input(format!(
            "`effects` must be a sequence of effect names (str), got {}",
            args::shown(effects)
        )));
    }
    overrides.apply(base(py, campaign)?)
}

/// A campaign as a dict (the JSON form drift-sim reads and writes to truth/campaign.json).
fn to_dict<'py>(py: Python<'py>, campaign: &Campaign) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(campaign)
        .map_err(|e| Error::Campaign(format!("internal: campaign JSON: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// The validated campaign `simulate` would run, as a dict (nothing is simulated).
#[pyfunction]
#[pyo3(signature = (
    campaign = None, *, seed = None, units = None, set_points = None, intervals = None,
    repeats = None, field = false, field_only = false, zero_drift = false, paper_exact = false,
    effects = None,
    noise_scale = None, truth_at_aux_rate = false,
))]
#[allow(clippy::too_many_arguments)]
pub fn resolve_campaign<'py>(
    py: Python<'py>,
    campaign: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    units: Option<&Bound<'py, PyAny>>,
    set_points: Option<&Bound<'py, PyAny>>,
    intervals: Option<&Bound<'py, PyAny>>,
    repeats: Option<&Bound<'py, PyAny>>,
    field: bool,
    field_only: bool,
    zero_drift: bool,
    paper_exact: bool,
    effects: Option<&Bound<'py, PyAny>>,
    noise_scale: Option<&Bound<'py, PyAny>>,
    truth_at_aux_rate: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let c = resolve(
        py,
        campaign,
        seed,
        units,
        set_points,
        intervals,
        repeats,
        field,
        field_only,
        zero_drift,
        paper_exact,
        effects,
        noise_scale,
        truth_at_aux_rate,
    )?;
    to_dict(py, &c)
}

/// Simulates a campaign into `out` (recordings/, truth/, summary.json), as `gyrodrift simulate`
/// does; returns the summary (files, samples, bytes, wall time) as a dict. The GIL is released.
#[pyfunction]
#[pyo3(signature = (
    out, campaign = None, *, seed = None, units = None, set_points = None, intervals = None,
    repeats = None, field = false, field_only = false, zero_drift = false, paper_exact = false,
    effects = None,
    noise_scale = None, truth_at_aux_rate = false,
))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    out: &Bound<'py, PyAny>,
    campaign: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    units: Option<&Bound<'py, PyAny>>,
    set_points: Option<&Bound<'py, PyAny>>,
    intervals: Option<&Bound<'py, PyAny>>,
    repeats: Option<&Bound<'py, PyAny>>,
    field: bool,
    field_only: bool,
    zero_drift: bool,
    paper_exact: bool,
    effects: Option<&Bound<'py, PyAny>>,
    noise_scale: Option<&Bound<'py, PyAny>>,
    truth_at_aux_rate: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let out = args::path("out", out)?;
    let c = resolve(
        py,
        campaign,
        seed,
        units,
        set_points,
        intervals,
        repeats,
        field,
        field_only,
        zero_drift,
        paper_exact,
        effects,
        noise_scale,
        truth_at_aux_rate,
    )?;
    let summary = py
        .detach(|| drift_sim::simulate_campaign(&c, &out, |_| {}))
        .map_err(Error::from)?;
    let text = serde_json::to_string(&summary)
        .map_err(|e| Error::Campaign(format!("internal: summary JSON: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}
