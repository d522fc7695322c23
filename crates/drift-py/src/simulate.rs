//! `gyrodrift.simulate` and `gyrodrift.resolve_campaign`: a campaign from a dict, TOML/JSON text or
//! a file, with keyword overrides that mean what `gyrodrift simulate`'s flags mean, simulated by
//! drift-sim into a folder (same campaign and seed → the same bytes as the command line).

use std::path::{Path, PathBuf};

use drift_recording::output_folder::Staged;
use drift_sim::output_folder::{summary_in_place, FolderError, SIMULATE};
use drift_sim::overrides::{parse_set_points, OverrideError, Overrides, SetPointsError};
use drift_sim::{Campaign, Protocol};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::args;
use crate::arrays::describe;
use crate::errors::Error;
use crate::interrupt;

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
        return parse_set_points(&text.to_string()).map_err(|error| match error {
            SetPointsError::EmptyRange(text) => {
                Error::Input(format!("`set_points` range {text:?} is empty"))
            }
            too_many @ SetPointsError::TooMany(..) => {
                Error::Input(format!("`set_points`: {too_many}"))
            }
            _ => bad(),
        });
    }
    args::value("set_points", EXPECTED, value)
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

/// A campaign from the JSON text of the dict given as `campaign`. An error names the dict's key at
/// fault (`campaign["units"]`), not a line and column of JSON text the caller never wrote.
fn from_dict(json: &str) -> Result<Campaign, Error> {
    let value: serde_json::Value = serde_json::from_str(json)
        .map_err(|e| Error::Campaign(format!("not a valid campaign: {e}")))?;
    serde_json::from_value(value.clone()).map_err(|error| {
        // Every field has a default: the first key that fails on its own is the one at fault.
        let key = value.as_object().and_then(|fields| {
            fields.iter().find_map(|(key, v)| {
                let alone =
                    serde_json::Value::Object([(key.clone(), v.clone())].into_iter().collect());
                serde_json::from_value::<Campaign>(alone)
                    .is_err()
                    .then(|| key.clone())
            })
        });
        Error::Campaign(match key {
            Some(key) => format!("not a valid campaign: `campaign[{key:?}]`: {error}"),
            None => format!("not a valid campaign: `campaign`: {error}"),
        })
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
        from_dict(&json)?
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
    overrides
        .apply(base(py, campaign)?)
        .map_err(|error| match error {
            OverrideError::Campaign(error) => error.into(),
            other => Error::Input(other.to_string()),
        })
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

/// A folder that cannot take the campaign: an I/O failure names the file, anything else is the
/// caller's input.
fn folder_error(error: FolderError) -> Error {
    match error {
        FolderError::Io {
            action,
            path,
            source,
        } => Error::File {
            action: match action {
                "reading" => "read",
                "writing" => "write",
                "renaming" => "rename",
                _ => "remove",
            },
            path,
            source,
        },
        other => Error::Input(other.to_string()),
    }
}

/// Simulates a campaign into `out` (recordings/, truth/, summary.json), as `gyrodrift simulate`
/// does: a folder that is not empty is refused unless `force` (then an earlier campaign there is
/// replaced once the new one is whole, and anything else refused), and a campaign writing more than `max_gb` is refused
/// before it is planned; returns the summary (files, samples, bytes, wall time) as a dict. The GIL is released;
/// Ctrl-C stops the run within a second and leaves `out` as it was; `progress(step, done, total)`
/// is called with the samples simulated.
#[pyfunction]
#[pyo3(signature = (
    out, campaign = None, *, seed = None, units = None, set_points = None, intervals = None,
    repeats = None, field = false, field_only = false, zero_drift = false, paper_exact = false,
    effects = None,
    noise_scale = None, truth_at_aux_rate = false, force = false, max_gb = 20.0, progress = None,
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
    force: bool,
    max_gb: f64,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let out = args::path("out", out)?;
    let progress = interrupt::callable(progress)?;
    if !(max_gb.is_finite() && max_gb > 0.0) {
        return Err(Error::Input(format!("`max_gb` must be > 0, got {max_gb}")).into());
    }
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
    let summary = interrupt::run(py, progress.as_ref(), |progress| -> Result<_, Error> {
        // Sized before anything is planned in full or written.
        drift_sim::size::within(&c, max_gb, "max_gb").map_err(|e| Error::Input(e.to_string()))?;
        // Written into a staging folder put in place at the end, as the command line does:
        // `force=True` replaces an earlier campaign only once the new one is whole.
        let staged = Staged::begin(&out, force, "force=True", &SIMULATE).map_err(folder_error)?;
        drift_sim::simulate_campaign_with(&c, staged.path(), progress)?;
        let text = summary_in_place(staged.path(), &out).map_err(folder_error)?;
        staged.commit().map_err(folder_error)?;
        Ok(text)
    })??;
    py.import("json")?.call_method1("loads", (summary,))
}
