//! `diagnosis.md` and `diagnosis.json`: the closed loop's report, written once for the command
//! line and the Python module ([`drift_diagnose::closing`] runs the loop; this renders it).
//!
//! One unit's (or one half's) [`Section`] is its Markdown, its JSON record, its console lines and
//! the files beside the report (the residual figures, the extended model's image); [`document`]
//! puts the sections together and [`write()`] writes them into a folder.

mod extended;
mod figures;
mod markdown;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use drift_diagnose::closing::Closed;
use drift_evaluate::noise_floor::Floor;
use drift_fit::{FitSettings, FittedUnit};
use serde::{Deserialize, Serialize};

use crate::write_atomic;
pub use markdown::agreement_markdown;
use markdown::{crossings_markdown, markdown, paper_markdown, profile_markdown};

/// What the analyst asked of the report, beyond the loop itself.
#[derive(Debug, Clone, Copy)]
pub struct Request<'r> {
    /// How many candidates to list per axis.
    pub top: usize,
    /// Whether the extended model was built (its section, its image).
    pub extend: bool,
    /// Set points whose protocol activations were also ranked on, °C.
    pub select_on: &'r [f64],
    /// The separate evaluation data, when the held-out activations came from there.
    pub evaluation_data: Option<&'r Path>,
}

/// One unit's (or one half's) part of the report (serialisable: Python's `Diagnosis` keeps it to
/// save later, and pickles with it).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Section {
    /// Its Markdown.
    pub markdown: String,
    /// Its record of `diagnosis.json`.
    /// (As JSON text: the section is also kept in postcard, which holds no untyped values.)
    pub json: String,
    /// What the command line prints of it.
    pub console: String,
    /// Files beside the report, by name: the residual figures, the extended model's image and
    /// JSON.
    pub files: Vec<(PathBuf, Vec<u8>)>,
}

/// What became of one unit's extended model, in the line `gyrodrift diagnose --extend` prints:
/// why nothing was extended (no term proposed, none admitted and why) or what was admitted.
pub fn extended_verdict(fitted: &FittedUnit, closed: &Closed<'_>) -> String {
    extended::verdict(&file_stem(fitted, closed), closed)
}

/// Files are named by unit and half, without the heading's spaces and commas.
fn file_stem(fitted: &FittedUnit, closed: &Closed<'_>) -> String {
    match closed.half {
        Some(half) => format!("{}-half{}", fitted.unit_id, half + 1),
        None => fitted.unit_id.clone(),
    }
}

/// Renders one unit's closed loop: `label` heads it (the unit, and the half when cross-fitted),
/// `settings` are the loop's fit settings, `floor` the noise floor beside the errors.
pub fn unit_section(
    label: &str,
    closed: &Closed<'_>,
    fitted: &FittedUnit,
    settings: &FitSettings,
    request: &Request<'_>,
    floor: Option<&Floor>,
) -> anyhow::Result<Section> {
    let unit = label;
    let mut md = String::new();
    let mut console = String::new();
    let mut files = Vec::new();
    let stem = file_stem(fitted, closed);
    let (activations, axes, roles) = (&closed.series, &closed.axes, &closed.roles);
    let _ = writeln!(md, "# Unit {unit}\n");
    {
        let _ = writeln!(
                md,
                "Diagnosed on {} activations the fit never saw ({}{}); {} field-like activations at the calibration set points switched on outside the calibrated ambient range (the model clamps there by design) and are {}.\n",
                activations.len(),
                if roles.training.is_empty() && roles.selection.is_empty() {
                    if roles.not_judged.is_empty() {
                        "every activation outside the calibration protocol"
                    } else {
                        "the calibration data's activations outside the calibration protocol"
                    }
                } else {
                    "field-like activations at the calibration set points"
                },
                if roles.selection.is_empty() {
                    String::new()
                } else {
                    format!(
                        " and {} protocol activations at {:?} °C, not measured on afterwards",
                        roles.selection.len(),
                        request.select_on
                    )
                } + &if roles.diagnosis.is_empty() {
                    String::new()
                } else {
                    format!(
                        "; and {} activations of this half of the analyst's diagnosis series, ranked, fitted and guarded on, while the other half's series are held out and judge",
                        roles.diagnosis.len()
                    )
                },
                roles.outside_range,
                if request.evaluation_data.is_some() {
                    "not judged on, as the calibration data's other activations".to_owned()
                } else {
                    format!("held out with the rest ({} held out in all)", roles.held_out.len())
                }
            );
        if let Some(dir) = &request.evaluation_data {
            let _ = writeln!(
                    md,
                    "Held out: the {} activations of the evaluation data `{}`; the calibration data's {} activations outside the roles above are not judged on.\n",
                    roles.held_out.len(),
                    dir.display(),
                    roles.not_judged.len()
                );
        }
    }
    // The held-out errors are needed by the crossings' table and the extended model's; a
    // unit with neither does not pay for correcting every held-out activation twice more.
    let before_after =
        if fitted.crossings.is_empty() && closed.extended.is_none() && !closed.keying.any() {
            Vec::new()
        } else {
            closed.before_after(fitted, settings)
        };
    let stage3 = &closed.stage3;
    let warm_start = &closed.warm_start;
    md.push_str(&crossings_markdown(
        fitted,
        stage3,
        warm_start,
        &before_after,
    ));
    md.push_str(&markdown(axes, request.top));
    // The plots show the ranking just above them (behind the loop's model), so they follow
    // it rather than the paper's ranking.
    md.push_str(&figures::residual_plots(
        &stem,
        activations,
        axes,
        &mut files,
    )?);
    if closed.keying.any() {
        md.push_str(&paper_markdown(&closed.paper_axes, request.top));
    }
    let _ = writeln!(console, "{unit}:");
    if let Some(dir) = &request.evaluation_data {
        let _ = writeln!(console,
                "  held out: {} activations of the evaluation data {} ({} of the calibration data's not judged on)",
                closed.roles.held_out.len(),
                dir.display(),
                closed.roles.not_judged.len()
            );
    }
    for crossing in &fitted.crossings {
        let _ = writeln!(console, "  tables: {}", crossing.note());
    }
    if stage3.iter().all(|c| c.training_activations == 0) {
        let _ = writeln!(console, "  stage 3: no field-like activations at the calibration set points to choose on; keyed by rise");
    }
    for c in stage3.iter().filter(|c| c.training_activations > 0) {
        let _ = writeln!(console,
                "  stage 3 on {}: drift on {} training activations {:.4} keyed by rise, {:.4} by history (p {:.1e}) → {}",
                c.axis,
                c.training_activations,
                c.training_drift_by_rise_dps,
                c.training_drift_by_history_dps,
                c.p_value,
                if c.keyed_by_history { "keyed by history" } else { "keyed by rise" }
            );
    }
    for c in warm_start.iter().filter(|c| c.training_activations > 0) {
        let _ = writeln!(console,
                "  initial bias on {}: RMS on {} training activations {:.4} with the paper's, {:.4} with warm starts' (p {:.1e}) → {}",
                c.axis,
                c.training_activations,
                c.training_rms_cold_dps,
                c.training_rms_warm_dps,
                c.p_value,
                if c.chosen { "warm starts'" } else { "the paper's" }
            );
    }
    if closed.keying.any() {
        for axis in &closed.paper_axes {
            let _ = writeln!(
                console,
                "  behind the paper's model, {}: {}",
                axis.axis,
                axis.ranking.first().map_or("–".to_owned(), |c| format!(
                    "{} explained {:.3}{}",
                    c.name,
                    c.explained,
                    if c.significant { ", significant" } else { "" }
                ))
            );
        }
    }
    for axis in axes.iter() {
        let chosen = if axis.selected.is_empty() {
            format!(
                    "nothing beyond the baseline (which explains {:.0} % within activations) and chance: with these activations only a gain above {:.0} % would show",
                    100.0 * axis.baseline_explained_within,
                    100.0 * axis.detectable_share
                )
        } else {
            markdown::selections(axis, &|c| {
                format!(
                    "{} (gain {:.0} % over the baseline; τ {:.0} %, p family {:.2})",
                    c.name,
                    100.0 * c.gain,
                    100.0
                        * if c.thermal_response {
                            axis.response_size_threshold
                        } else {
                            axis.size_threshold
                        },
                    c.family_p_value
                )
            })
        };
        let _ = writeln!(console, "  {}: {chosen}", axis.axis);
        for (i, c) in axis.ranking.iter().take(request.top).enumerate() {
            let _ = writeln!(
                console,
                "     {}. {:<42} {:<20} gain {:>6.3}  p family {:.2}{}",
                i + 1,
                c.name,
                c.level,
                c.explained,
                c.family_p_value,
                if c.significant { "  *" } else { "" }
            );
        }
    }
    if request.extend {
        let _ = writeln!(
            console,
            "  extended model: {}",
            extended::verdict(&stem, closed)
        );
    }
    let profiles = closed.profiles(fitted, settings);
    md.push_str(&profile_markdown(&profiles));
    if request.extend {
        md.push_str(&extended::run(
            &stem,
            closed,
            fitted,
            &before_after,
            floor,
            &mut files,
        )?);
    }
    let json = serde_json::json!({
        "unit": &fitted.unit_id,
        "half": closed.half,
        "axes": axes,
        "paper_axes": &closed.paper_axes,
        "proposed_terms": closed.proposed.terms.iter().map(|t| &t.candidate).collect::<Vec<_>>(),
        "admissions": closed.extended.as_ref().map(|e| &e.admissions),
        "switch_on_rate": closed.extended.is_some().then_some(&closed.switch_on_rate),
        "crossings": fitted.crossings,
        "stage3": stage3,
        "warm_start": warm_start,
        "before_after": before_after,
        // The per-group table of the Markdown, with the noise floor and each excess cut's
        // interval, as data.
        "held_out_error": drift_diagnose::before_after::group_errors(&before_after, floor),
        "noise_floor_given": floor.is_some(),
        "profiles": profiles,
    });
    Ok(Section {
        markdown: md,
        json: serde_json::to_string(&json)?,
        console,
        files,
    })
}

/// The whole `diagnosis.md`: the heading, `preamble` (what the data were), each section, and the
/// halves' agreement (`agreement`, from [`agreement_markdown`]).
pub fn document(preamble: &str, sections: &[Section], agreement: &str) -> String {
    let mut md = String::from("# gyrodrift diagnosis\n\n");
    md.push_str(preamble);
    for section in sections {
        md.push_str(&section.markdown);
    }
    md.push_str(agreement);
    md
}

/// Writes `diagnosis.md`, `diagnosis.json` and every section's files into `out` (created if
/// missing), each file whole or not at all.
pub fn write(out: &Path, document: &str, sections: &[Section]) -> anyhow::Result<()> {
    std::fs::create_dir_all(out)?;
    for section in sections {
        for (name, bytes) in &section.files {
            write_atomic(&out.join(name), bytes)?;
        }
    }
    let json = sections
        .iter()
        .map(|s| serde_json::from_str(&s.json))
        .collect::<Result<Vec<serde_json::Value>, _>>()?;
    write_atomic(
        &out.join("diagnosis.json"),
        serde_json::to_string_pretty(&json)?.as_bytes(),
    )?;
    write_atomic(&out.join("diagnosis.md"), document.as_bytes())?;
    Ok(())
}
