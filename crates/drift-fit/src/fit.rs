//! Activations of one unit → the paper's tables and the two baselines.

use std::collections::BTreeSet;

use drift_core::{
    AmbientCurves, AxisTable, Curve, CurvePoint, Model, ModifiedTables, PolynomialTables,
    RecommendedTables, RelativePolynomialTables, Settings, WarmStart,
};
use nalgebra::{Matrix2, Vector2};

use crate::analyse::Analysed;
use crate::baselines::{self, HELD_OUT_BAND_CELSIUS};
use crate::curves::{group, AveragedCurve, CurveKey, SetPointCurves};
use crate::error::FitError;
use crate::history_order::{crossings, Crossing};
use crate::knots::{choose, k_window, mean_window};
use crate::parallel::per_axis;
use crate::settings::FitSettings;
use drift_recording::{SCALE_KEY, ZERO_KEY};

/// Capacities of the host table type (`ModifiedTables`'s defaults).
const MAX_REFERENCES: usize = 16;
const MAX_AMBIENTS: usize = 12;
const MAX_CURVES: usize = 32;
type Table = AxisTable<MAX_REFERENCES, MAX_AMBIENTS, MAX_CURVES>;
/// Smallest temperature rise (°C) that counts as heating: ten raw sensor steps.
const MIN_RISE_CELSIUS: f64 = 0.05;

/// Everything fitted for one unit.
#[derive(Debug, Clone, PartialEq)]
pub struct FittedUnit {
    /// Unit id.
    pub unit_id: String,
    /// The paper's ("modified") tables.
    pub modified: ModifiedTables,
    /// The same curves with stage 3 keyed by heating history (each curve labelled by the residual
    /// heat it switched on with) instead of by rise, and the initial bias of warm starts
    /// (`drift_core::AmbientCurves::warm_starts`): for firmware that keeps what it knew of the
    /// previous activation across power-off (`drift_core::CorrectorState::power_on_after`).
    pub by_history: ModifiedTables,
    /// The recommended model: the paper's curves (as `modified`) with the turn-on bias fitted on
    /// every calibration activation ([`crate::turn_on`]).
    pub recommended: RecommendedTables,
    /// The paper's standard calibration (Lagrange through the set points).
    pub standard: PolynomialTables,
    /// The least-squares polynomial baseline (3rd order by default).
    pub third_order: PolynomialTables,
    /// The least-squares polynomial baseline relative to the switch-on (turn-on bias `q(T_on)`,
    /// drift `p(T) − p(T_on)`), orders up to the cubic chosen by cross-validation over held-out
    /// temperature bands.
    pub relative: RelativePolynomialTables,
    /// The same form with `p` and `q` cubic (PX4's and ArduPilot's order, relative to the
    /// switch-on).
    pub relative_cubic: RelativePolynomialTables,
    /// The averaged curves the tables were built from (for plots and diagnosis).
    pub set_points: Vec<SetPointCurves>,
    /// The curve keys kept, in table order before the per-reference-time sort.
    pub curve_keys: Vec<CurveKey>,
    /// Things the fit decided or found that a reader should know (dropped curves, nudged ties,
    /// the crossings below).
    pub notes: Vec<String>,
    /// Where the rise fails to tell heating histories apart (stage 3's premise), worst per set
    /// point × axis; empty when it holds.
    pub crossings: Vec<Crossing>,
}

fn check(settings: &FitSettings) -> Result<(), FitError> {
    let bad = |field, problem: &str| {
        Err(FitError::Settings {
            field,
            problem: problem.into(),
        })
    };
    if !(settings.lowpass_window_s.is_finite() && settings.lowpass_window_s > 0.0) {
        return bad(
            "lowpass_window_s",
            "must be a positive number of seconds (1 in the paper)",
        );
    }
    if settings.grid_ms == 0 {
        return bad("grid_ms", "must be at least 1");
    }
    if !(2..=MAX_REFERENCES).contains(&settings.reference_count) {
        return bad(
            "reference_count",
            "must be between 2 and 16 (the table's capacity)",
        );
    }
    if settings.polynomial_degree > 7 {
        return bad(
            "polynomial_degree",
            "must be at most 7 (8 coefficients in the image)",
        );
    }
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if !positive(settings.first_reference_s) {
        return bad("first_reference_s", "must be a positive number of seconds");
    }
    if !positive(settings.initial_bias_window_s) {
        return bad(
            "initial_bias_window_s",
            "must be a positive number of seconds",
        );
    }
    Ok(())
}

/// Makes `values` strictly increasing by nudging ties upwards by a relative 1e-6 (at most a few
/// µ°C: far below the sensor's resolution). Returns how many were nudged.
fn strictly_increasing(values: &mut [f32]) -> usize {
    let mut nudged = 0;
    for i in 1..values.len() {
        if values[i] <= values[i - 1] {
            values[i] = values[i - 1] + (values[i - 1].abs() * 1e-6).max(1e-6);
            nudged += 1;
        }
    }
    nudged
}

/// How stage 3 finds its curves in a fitted table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage3 {
    /// The paper's: by the current rise (curves sorted by rise at every reference time).
    ByRise,
    /// By the residual heat at switch-on (curves in order of it, labelled with it).
    ByHistory,
}

/// The residual heat curve `c` of `sp` switched on with on `axis`, °C: how far its mean switch-on
/// temperature stood above the set point's ambient (the independent starts' mean), which is what
/// firmware estimates from what it kept of the previous activation.
fn residual_heat(sp: &SetPointCurves, c: usize, axis: usize) -> f64 {
    sp.curves[c].switch_on_celsius[axis] - sp.ambient_celsius[axis]
}

/// The curves' order for a table keyed by history, the same at every set point (stage 2 blends
/// curve `c` of one ambient with curve `c` of the next): by residual heat averaged over the set
/// points, as indices into each set point's curves (which share their keys and order).
fn order_by_residual_heat(set_points: &[SetPointCurves], axis: usize) -> Vec<usize> {
    let count = set_points.first().map_or(0, |sp| sp.curves.len());
    let mean = |c: usize| {
        set_points
            .iter()
            .map(|sp| residual_heat(sp, c, axis))
            .sum::<f64>()
            / set_points.len().max(1) as f64
    };
    let mut order: Vec<usize> = (0..count).collect();
    order.sort_by(|&a, &b| mean(a).total_cmp(&mean(b)));
    order
}

/// The table of one axis (reference times, then per set point the curves' rise and `k` there):
/// sorted by rise at every reference time for the paper's stage 3, or in order of residual heat,
/// labelled with it, for a stage 3 keyed by history; with the notes it leaves. The error says why
/// there is none.
///
/// Boxed: the table (~50 KB) crosses rayon's join, whose frames hold its result, and rayon's
/// worker threads have 2 MiB stacks.
fn axis_table(
    set_points: &[SetPointCurves],
    axis: usize,
    first: usize,
    settings: &FitSettings,
    stage3: Stage3,
    given: Option<&[usize]>,
) -> Result<(Box<Table>, Vec<String>), String> {
    let window = settings.reference_window_points;
    let mut table = Box::<Table>::default();
    let mut notes = Vec::new();
    let shortest = set_points
        .iter()
        .flat_map(|sp| sp.curves.iter())
        .map(|c| c.len())
        .min()
        .unwrap_or(0);
    let knots = match given {
        Some(knots) => {
            if let Some(&late) = knots.iter().find(|&&j| j >= shortest) {
                return Err(format!(
                    "axis {axis}: the given reference time {} ms lies after the shortest curve's end ({} ms)",
                    late as u64 * u64::from(settings.grid_ms),
                    shortest as u64 * u64::from(settings.grid_ms)
                ));
            }
            knots.to_vec()
        }
        None => choose(set_points, axis, first, settings.reference_count, window),
    };
    for &j in &knots {
        let _ = table.reference_ms.push(j as u32 * settings.grid_ms);
    }
    let order = order_by_residual_heat(set_points, axis);
    let mut last_ambient = f32::NEG_INFINITY;
    for sp in set_points {
        let mut ambient = AmbientCurves {
            ambient_celsius: sp.ambient_celsius[axis] as f32,
            initial_bias_dps: sp.initial_bias_dps[axis] as f32,
            curves: heapless::Vec::new(),
            residual_heat_celsius: heapless::Vec::new(),
            warm_starts: heapless::Vec::new(),
        };
        if ambient.ambient_celsius <= last_ambient {
            return Err(format!(
                "axis {axis}: switch-on temperature at {} °C ({:.3} °C) is not above the previous set point's",
                sp.set_point_celsius, ambient.ambient_celsius
            ));
        }
        last_ambient = ambient.ambient_celsius;
        let curves: Vec<&AveragedCurve> = match stage3 {
            Stage3::ByRise => sp.curves.iter().collect(),
            Stage3::ByHistory => order.iter().map(|&c| &sp.curves[c]).collect(),
        };
        // Points per reference time.
        let mut columns: Vec<Vec<(f32, f32)>> = knots
            .iter()
            .map(|&j| {
                curves
                    .iter()
                    .map(|c| {
                        (
                            mean_window(&c.rise_celsius[axis], j, window) as f32,
                            k_window(&c.drift_dps[axis], &c.rise_celsius[axis], j, window) as f32,
                        )
                    })
                    .collect()
            })
            .collect();
        match stage3 {
            Stage3::ByRise => {
                // Sorted by rise at every reference time: the paper's stage 3 searches them.
                for (j, column) in columns.iter_mut().enumerate() {
                    column.sort_by(|a, b| a.0.total_cmp(&b.0));
                    let mut rises: Vec<f32> = column.iter().map(|p| p.0).collect();
                    let nudged = strictly_increasing(&mut rises);
                    if nudged > 0 {
                        notes.push(format!(
                            "axis {axis}, {} °C, reference {j}: {nudged} tied rises nudged",
                            sp.set_point_celsius
                        ));
                    }
                    for (point, rise) in column.iter_mut().zip(rises) {
                        point.0 = rise;
                    }
                }
            }
            Stage3::ByHistory => {
                let mut heats: Vec<f32> = order
                    .iter()
                    .map(|&c| residual_heat(sp, c, axis) as f32)
                    .collect();
                let nudged = strictly_increasing(&mut heats);
                if nudged > 0 {
                    notes.push(format!(
                        "axis {axis}, {} °C, keyed by history: {nudged} residual heat(s) nudged up to keep the order the curves share across set points",
                        sp.set_point_celsius
                    ));
                }
                for heat in heats {
                    let _ = ambient.residual_heat_celsius.push(heat);
                }
            }
        }
        for c in 0..curves.len() {
            let mut curve = Curve::default();
            for column in &columns {
                let (rise, k) = column[c];
                let _ = curve.points.push(CurvePoint {
                    rise_celsius: rise,
                    k_dps_per_celsius: k,
                });
            }
            let _ = ambient.curves.push(curve);
        }
        let _ = table.ambients.push(ambient);
    }
    if stage3 == Stage3::ByHistory {
        add_warm_starts(&mut table, set_points, axis);
    }
    Ok((table, notes))
}

/// Warm starts stored per ambient: the smoothed offset at this many residual heats, evenly spaced
/// up to the warmest calibration start.
const WARM_START_POINTS: usize = 4;

/// Gives a table keyed by history the initial bias of its warm starts, per set point: how far each
/// history that switched on with residual heat started from the cold starts' initial bias,
/// smoothed over the histories ([`smooth_warm_starts`]).
fn add_warm_starts(table: &mut Table, set_points: &[SetPointCurves], axis: usize) {
    for (ambient, sp) in table.ambients.iter_mut().zip(set_points) {
        let starts: Vec<(f64, f64, f64)> = sp
            .curves
            .iter()
            .enumerate()
            .map(|(c, curve)| {
                (
                    residual_heat(sp, c, axis),
                    curve.initial_bias_dps[axis] - sp.initial_bias_dps[axis],
                    curve.members as f64,
                )
            })
            .filter(|(heat, offset, _)| *heat > 0.0 && offset.is_finite())
            .collect();
        ambient.warm_starts = smooth_warm_starts(&starts);
    }
}

/// The warm starts of one ambient from its histories' `(residual heat, offset, activations)`: the
/// weighted least-squares `offset = a·h + b·h²` (`a·h` alone with fewer than three histories),
/// sampled at [`WARM_START_POINTS`] residual heats up to the warmest.
///
/// Why smoothed: each history's initial bias is the mean of a few activations, each with its own
/// turn-on jitter, and histories of nearly equal residual heat (a long interval's later
/// activations) would make a table that zig-zags through that noise. The offset itself is smooth
/// in the residual heat: the sensor's temperature above the ambient (through the cold starts'
/// slope) and the element's lag behind it, both of which fade together as the unit cools. Through
/// the origin: a cold start is the cold starts' own initial bias.
fn smooth_warm_starts(starts: &[(f64, f64, f64)]) -> heapless::Vec<WarmStart, MAX_CURVES> {
    let warmest = starts.iter().map(|s| s.0).fold(0.0, f64::max);
    let sum = |f: &dyn Fn(f64, f64) -> f64| starts.iter().map(|&(h, o, w)| w * f(h, o)).sum();
    let (hh, hh2, h2h2) = (
        sum(&|h, _| h * h),
        sum(&|h, _| h * h * h),
        sum(&|h, _| h * h * h * h),
    );
    let (ho, h2o) = (sum(&|h, o| h * o), sum(&|h, o| h * h * o));
    let quadratic = (starts.len() >= 3)
        .then(|| Matrix2::new(hh, hh2, hh2, h2h2).try_inverse())
        .flatten()
        .map(|inverse| inverse * Vector2::new(ho, h2o));
    let (a, b) = match quadratic {
        Some(ab) => (ab[0], ab[1]),
        None if hh > 0.0 => (ho / hh, 0.0),
        None => return heapless::Vec::new(),
    };
    (1..=WARM_START_POINTS)
        .map(|i| {
            let h = warmest * i as f64 / WARM_START_POINTS as f64;
            WarmStart {
                residual_heat_celsius: h as f32,
                bias_offset_dps: (a * h + b * h * h) as f32,
            }
        })
        .filter(|w| w.residual_heat_celsius > 0.0)
        .collect()
}

/// Fits one unit from its analysed activations (calibration set points only: the caller keeps the
/// validation data out).
pub fn fit_unit(activations: &[Analysed], settings: &FitSettings) -> Result<FittedUnit, FitError> {
    fit_unit_at(activations, settings, None)
}

/// The reference times of `tables`, per axis, as indices of the analysis grid of `settings`: what
/// [`fit_unit_at`] takes to fit other quantities at the same reference times.
pub fn reference_indices(tables: &ModifiedTables, settings: &FitSettings) -> [Vec<usize>; 3] {
    let grid_ms = settings.grid_ms.max(1);
    std::array::from_fn(|axis| {
        tables.axes[axis]
            .reference_ms
            .iter()
            .map(|&ms| (ms / grid_ms) as usize)
            .collect()
    })
}

/// [`fit_unit`] with the reference times given per axis (grid indices, [`reference_indices`])
/// instead of chosen from the data, or chosen when `references` is `None`.
///
/// Why: for fixed reference times the paper's fit — the initial bias (an intercept), `k` at each
/// reference time (a mean of drift over rise), the warm starts (least squares) — is linear in the
/// rates, and so is the corrector's prediction. The tables fitted to a quantity `x` at the
/// reference times the drift fit chose are then exactly what the drift's tables take of `x`: the
/// paper leaves `c·(x − L x)` of a bias `g + c·x` beside what it leaves of `g`. Chosen afresh for
/// `x`, the reference times differ and that identity is lost.
pub fn fit_unit_at(
    activations: &[Analysed],
    settings: &FitSettings,
    references: Option<&[Vec<usize>; 3]>,
) -> Result<FittedUnit, FitError> {
    check(settings)?;
    let unit_id = activations
        .first()
        .map(|a| a.labels.unit_id.clone())
        .unwrap_or_default();
    let insufficient = |what: String| FitError::Insufficient {
        unit: unit_id.clone(),
        what,
    };
    if let Some(other) = activations.iter().find(|a| a.labels.unit_id != unit_id) {
        return Err(insufficient(format!(
            "activations of another unit ({}) were passed in",
            other.labels.unit_id
        )));
    }
    let scale = activations
        .first()
        .map(|a| a.temperature_scale)
        .unwrap_or_default();
    if let Some(other) = activations.iter().find(|a| a.temperature_scale != scale) {
        return Err(insufficient(format!(
            "its recordings give two temperature scales ({} and {} raw/°C, {} and {} raw at \
             0 °C; {SCALE_KEY} and {ZERO_KEY} in the recording metadata): one sensor has one",
            scale.raw_per_celsius,
            other.temperature_scale.raw_per_celsius,
            scale.raw_at_zero_celsius,
            other.temperature_scale.raw_at_zero_celsius,
        )));
    }
    // The activations' analysis grid: the settings' own, or a multiple of it where that is not a
    // whole number of samples at their rate (`FitSettings::grid_at`). Reference times are its points.
    let grid_ms = activations.first().map_or(settings.grid_ms, |a| a.grid_ms);
    if let Some(other) = activations.iter().find(|a| a.grid_ms != grid_ms) {
        let first = activations.first().map_or(0, |a| a.sample_rate_hz);
        return Err(insufficient(format!(
            "its activations were analysed on grids of {grid_ms} and {} ms (recorded at {first} and \
             {} Hz): fit the activations of one rate, or bring them to one (block means)",
            other.grid_ms, other.sample_rate_hz
        )));
    }
    let mut notes = Vec::new();
    let on_grid;
    let settings = if grid_ms == settings.grid_ms {
        settings
    } else {
        if references.is_some() {
            return Err(insufficient(format!(
                "reference times were given on the {} ms grid, the activations were analysed on \
                 {grid_ms} ms",
                settings.grid_ms
            )));
        }
        notes.push(format!(
            "analysis grid {grid_ms} ms: {} ms is not a whole number of samples at {} Hz",
            settings.grid_ms,
            activations.first().map_or(0, |a| a.sample_rate_hz)
        ));
        on_grid = FitSettings {
            grid_ms,
            ..settings.clone()
        };
        &on_grid
    };
    let mut set_points = group(activations, settings);
    if set_points.is_empty() {
        return Err(insufficient("no protocol activations to fit".into()));
    }
    if set_points.len() > MAX_AMBIENTS {
        return Err(insufficient(format!(
            "{} set points exceed the table's {MAX_AMBIENTS} ambients",
            set_points.len()
        )));
    }
    // Curves must correspond across ambients: keep the keys every set point has.
    let mut common: BTreeSet<CurveKey> = set_points[0].curves.iter().map(|c| c.key).collect();
    for sp in &set_points[1..] {
        let keys: BTreeSet<CurveKey> = sp.curves.iter().map(|c| c.key).collect();
        common = common.intersection(&keys).copied().collect();
    }
    if !common.contains(&CurveKey::Independent) {
        return Err(insufficient(
            "a set point has no independent (first, fully cooled) activation".into(),
        ));
    }
    for sp in &mut set_points {
        let before = sp.curves.len();
        sp.curves.retain(|c| common.contains(&c.key));
        if sp.curves.len() < before {
            notes.push(format!(
                "{} °C: {} curves dropped (not present at every set point)",
                sp.set_point_celsius,
                before - sp.curves.len()
            ));
        }
    }
    if common.len() > MAX_CURVES {
        return Err(insufficient(format!(
            "{} curves exceed the table's {MAX_CURVES}",
            common.len()
        )));
    }
    let grid_ms = settings.grid_ms;
    let first = (settings.first_reference_s * 1000.0 / f64::from(grid_ms)).round() as usize;
    let shortest = set_points
        .iter()
        .flat_map(|sp| sp.curves.iter())
        .map(|c| c.len())
        .min()
        .unwrap_or(0);
    if shortest <= first + 1 {
        return Err(insufficient(format!(
            "activations end before the first reference time ({} s)",
            settings.first_reference_s
        )));
    }
    // Without heating there is nothing to correlate the drift with: say so instead of fitting k = 0.
    for axis in 0..3 {
        let heated = set_points.iter().flat_map(|sp| sp.curves.iter()).any(|c| {
            c.rise_celsius[axis]
                .iter()
                .any(|r| r.abs() >= MIN_RISE_CELSIUS)
        });
        if !heated {
            return Err(insufficient(format!(
                "axis {}: the temperature never rises by {MIN_RISE_CELSIUS} °C in any activation (stuck or missing temperature sensor?): no heating to correlate the drift with",
                ["X", "Y", "Z"][axis]
            )));
        }
    }
    let crossings = crossings(&set_points, first);
    notes.extend(crossings.iter().map(Crossing::note));
    let protocol: Vec<&Analysed> = activations
        .iter()
        .filter(|a| CurveKey::of(a, settings).is_some())
        .collect();
    let by_set_point: Vec<Vec<&Analysed>> = set_points
        .iter()
        .map(|sp| {
            protocol
                .iter()
                .copied()
                .filter(|a| (a.labels.set_point_celsius - sp.set_point_celsius).abs() < 1e-6)
                .collect()
        })
        .collect();
    // The tables convert raw readings as the calibration recordings did, and state their sample
    // rate for firmware to check its own against (0, not stated, when the recordings differ).
    let rate = activations.first().map_or(0, |a| a.sample_rate_hz);
    let rate = if activations.iter().all(|a| a.sample_rate_hz == rate) {
        rate
    } else {
        0
    };
    let core_settings = Settings {
        raw_per_celsius: scale.raw_per_celsius as f32,
        raw_at_zero_celsius: scale.raw_at_zero_celsius as f32,
        sample_rate_hz: rate as f32,
        ..Settings::default()
    };
    // The axes' tables and the baselines are independent: all on rayon's threads at once.
    let (tables, ((standard, third_order), ((relative, relative_orders), relative_cubic))) =
        rayon::join(
            || {
                per_axis(|axis| {
                    let given = references.map(|r| r[axis].as_slice());
                    let by_rise =
                        axis_table(&set_points, axis, first, settings, Stage3::ByRise, given)?;
                    let by_history =
                        axis_table(&set_points, axis, first, settings, Stage3::ByHistory, given)?;
                    Ok::<_, String>((by_rise, by_history))
                })
            },
            || {
                rayon::join(
                    || {
                        rayon::join(
                            || baselines::standard(&by_set_point, core_settings),
                            || {
                                baselines::least_squares_polynomial(
                                    &protocol,
                                    settings.polynomial_degree,
                                    core_settings,
                                )
                            },
                        )
                    },
                    || {
                        rayon::join(
                            || baselines::relative_polynomial(&protocol, core_settings),
                            || baselines::relative_cubic(&protocol, core_settings),
                        )
                    },
                )
            },
        );
    let mut axes: [Table; 3] = Default::default();
    let mut history_axes: [Table; 3] = Default::default();
    for ((table, history_table), fitted) in axes.iter_mut().zip(&mut history_axes).zip(tables) {
        let ((fitted, axis_notes), (by_history, history_notes)) = fitted.map_err(insufficient)?;
        *table = *fitted;
        *history_table = *by_history;
        notes.extend(axis_notes);
        notes.extend(history_notes);
    }
    let modified = ModifiedTables {
        settings: core_settings,
        axes,
        extension: drift_core::Extension::NONE,
    };
    let by_history = ModifiedTables {
        settings: core_settings,
        axes: history_axes,
        extension: drift_core::Extension::NONE,
    };
    for (model, tables) in [("modified", &modified), ("by_history", &by_history)] {
        tables.validate().map_err(|source| FitError::Table {
            unit: unit_id.clone(),
            model,
            source,
        })?;
    }

    let recommended = RecommendedTables::try_new(&modified, crate::turn_on::turn_on(&protocol))
        .map_err(|source| FitError::Table {
            unit: unit_id.clone(),
            model: "recommended",
            source,
        })?;
    for (model, tables) in [("standard", &standard), ("third_order", &third_order)] {
        tables.validate().map_err(|source| FitError::Table {
            unit: unit_id.clone(),
            model,
            source,
        })?;
    }
    for (model, tables) in [("relative", &relative), ("relative_cubic", &relative_cubic)] {
        tables.validate().map_err(|source| FitError::Table {
            unit: unit_id.clone(),
            model,
            source,
        })?;
    }
    notes.push(format!(
        "relative baseline: orders by cross-validation over held-out {HELD_OUT_BAND_CELSIUS} °C temperature bands of the calibration, up to the cubic: drift p(T) of degree {} and turn-on bias q(T_on) of degree {} (X, Y, Z)",
        relative_orders
            .iter()
            .map(|o| o.0.to_string())
            .collect::<Vec<_>>()
            .join("/"),
        relative_orders
            .iter()
            .map(|o| o.1.to_string())
            .collect::<Vec<_>>()
            .join("/"),
    ));
    Ok(FittedUnit {
        unit_id,
        modified,
        by_history,
        recommended,
        standard,
        third_order,
        relative,
        relative_cubic,
        curve_keys: common.into_iter().collect(),
        set_points,
        notes,
        crossings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warm_starts_are_the_histories_offsets_smoothed_through_a_cold_start() {
        // Offsets on 0.004·h − 0.0005·h², with ±0.001 of turn-on jitter that averages out.
        let truth = |h: f64| 0.004 * h - 0.0005 * h * h;
        let starts: Vec<(f64, f64, f64)> = [0.1, 0.1, 0.4, 0.45, 1.0, 1.3, 1.6, 2.2, 2.5]
            .iter()
            .enumerate()
            .map(|(i, &h)| (h, truth(h) + if i % 2 == 0 { 0.001 } else { -0.001 }, 2.0))
            .collect();
        let warm = smooth_warm_starts(&starts);
        assert_eq!(warm.len(), WARM_START_POINTS);
        assert_eq!(warm.last().unwrap().residual_heat_celsius, 2.5);
        for w in &warm {
            let h = f64::from(w.residual_heat_celsius);
            assert!(
                (f64::from(w.bias_offset_dps) - truth(h)).abs() < 6e-4,
                "{w:?}"
            );
        }
        assert!(warm
            .windows(2)
            .all(|p| p[0].residual_heat_celsius < p[1].residual_heat_celsius));
        // Two histories: a line through the origin; none (or no heat): nothing to store.
        let line = smooth_warm_starts(&[(1.0, 0.002, 1.0), (2.0, 0.004, 1.0)]);
        assert!((line[3].bias_offset_dps - 0.004).abs() < 1e-9);
        assert!((line[0].bias_offset_dps - 0.001).abs() < 1e-9);
        assert!(smooth_warm_starts(&[]).is_empty());
    }
}
