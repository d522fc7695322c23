//! Realistic synthetic tables for tests, test vectors and the firmware: 3 axes, 3 ambients,
//! 16 heating-dynamics curves and 8 reference times (the size `docs/embedded.md` reports).
//!
//! Shapes follow the paper and the simulator's physics, not any fit: rise `R_c (1 − e^(−t/τ))` with
//! larger final rises for "fresher" (longer-off) curves, and `k` decaying from an early overshoot,
//! slightly larger for curves that heat more. Values are rounded to 5 decimals so their JSON text
//! round-trips to the same f32 in every language.

use drift_core::{
    AmbientCurves, AxisTable, Curve, CurvePoint, ModifiedTables, PolynomialAxis, PolynomialTables,
    RecommendedTables, Settings, SwitchOnRate, TurnOn, WarmStart,
};

/// Reference times, ms.
pub const REFERENCE_MS: [u32; 8] = [
    2_000, 5_000, 10_000, 20_000, 30_000, 60_000, 90_000, 120_000,
];
/// Calibration ambients, °C.
pub const AMBIENTS: [f32; 3] = [20.0, 30.0, 40.0];
/// Curves per ambient.
pub const CURVES: usize = 16;

/// Capacities sized exactly for the fixture (what the firmware uses).
pub type FixtureTables = ModifiedTables<8, 3, 16>;

/// Settings of the fixture: the defaults, but a short stuck-sensor limit so a test case can reach it.
pub fn settings() -> Settings {
    Settings {
        stuck_after_samples: 20,
        ..Settings::default()
    }
}

fn round5(x: f64) -> f32 {
    ((x * 1e5).round() / 1e5) as f32
}

/// Rounds to 6 significant digits (for small values such as `k`).
fn round_sig(x: f64) -> f32 {
    let scale = 10_f64.powi(5 - x.abs().log10().floor() as i32);
    ((x * scale).round() / scale) as f32
}

/// Per-axis character: (k scale (°/s)/°C, initial bias °/s, initial-bias slope (°/s)/°C).
const AXIS: [(f64, f64, f64); 3] = [
    (0.0042, 0.120, 0.0020),
    (-0.0031, -0.045, 0.0012),
    (0.0055, 0.010, -0.0016),
];

/// Final rise of curve `c` at ambient `ambient` after 2 min, °C.
pub fn final_rise(c: usize, ambient: f32) -> f64 {
    (1.5 + 0.3 * c as f64) * (1.0 - 0.005 * (f64::from(ambient) - 30.0))
}

/// The modified-model fixture.
pub fn modified() -> FixtureTables {
    let axes = core::array::from_fn(|axis| {
        let (k_scale, bias0, bias_slope) = AXIS[axis];
        let mut table = AxisTable {
            reference_ms: heapless::Vec::from_slice(&REFERENCE_MS).unwrap(),
            ..AxisTable::default()
        };
        for &ambient in &AMBIENTS {
            let mut at = AmbientCurves {
                ambient_celsius: ambient,
                initial_bias_dps: round5(bias0 + bias_slope * (f64::from(ambient) - 30.0)),
                curves: heapless::Vec::new(),
                residual_heat_celsius: heapless::Vec::new(),
                warm_starts: heapless::Vec::new(),
            };
            for c in 0..CURVES {
                let mut curve = Curve::default();
                for &ms in &REFERENCE_MS {
                    let t = f64::from(ms) / 1000.0;
                    let rise = final_rise(c, ambient) * (1.0 - (-t / 60.0).exp())
                        / (1.0 - (-2.0_f64).exp());
                    let k = k_scale
                        * (1.0 + 0.4 * (-t / 20.0).exp())
                        * (0.85 + 0.15 * c as f64 / (CURVES - 1) as f64)
                        * (1.0 + 0.01 * (f64::from(ambient) - 30.0));
                    let point = CurvePoint {
                        rise_celsius: round5(rise),
                        k_dps_per_celsius: round_sig(k),
                    };
                    curve.points.push(point).unwrap();
                }
                at.curves.push(curve).unwrap();
            }
            table.ambients.push(at).unwrap();
        }
        table
    });
    ModifiedTables::try_new(settings(), axes).unwrap()
}

/// A "standard" baseline: Lagrange through the bias at the three ambients (degree 2).
pub fn standard() -> PolynomialTables {
    let axes = core::array::from_fn(|axis| {
        let (_, bias0, slope) = AXIS[axis];
        PolynomialAxis {
            range_celsius: [20.0, 40.0],
            coefficients: heapless::Vec::from_slice(&[
                round5(bias0 + 0.004),
                round5(slope * 10.0),
                round5(0.003),
            ])
            .unwrap(),
        }
    });
    PolynomialTables::try_new(settings(), axes).unwrap()
}

/// A 3rd-order baseline (PX4/ArduPilot practice).
pub fn third_order() -> PolynomialTables {
    let axes = core::array::from_fn(|axis| {
        let (_, bias0, slope) = AXIS[axis];
        PolynomialAxis {
            range_celsius: [18.0, 48.0],
            coefficients: heapless::Vec::from_slice(&[
                round5(bias0 + 0.006),
                round5(slope * 15.0),
                round5(0.004),
                round5(-0.0015),
            ])
            .unwrap(),
        }
    });
    PolynomialTables::try_new(settings(), axes).unwrap()
}

/// The extended-model fixture: the modified tables plus one extra term of each kind, with
/// coefficients of the size the closed loop fits (°/s per unit of the term).
pub fn extended() -> FixtureTables {
    use drift_core::{Extension, ExtraTerm, Term};
    let terms = [
        ExtraTerm {
            term: Term::TemperatureRate {
                time_constant_ms: 5000,
            },
            centre: [0.01, 0.012, 0.008],
            coefficient: [0.1, -0.08, 0.05],
        },
        ExtraTerm {
            term: Term::Aux {
                input: 0,
                time_constant_ms: 2000,
            },
            centre: [5.0; 3],
            coefficient: [0.01, -0.012, 0.008],
        },
        ExtraTerm {
            term: Term::AxisRise { axis: 0 },
            centre: [2.0; 3],
            coefficient: [0.0, 0.002, -0.0015],
        },
        ExtraTerm {
            term: Term::RiseSquared,
            centre: [6.0, 7.0, 5.0],
            coefficient: [0.0003, -0.0002, 0.0001],
        },
    ];
    let extension = Extension {
        terms: heapless::Vec::from_slice(&terms).unwrap(),
        // A unit that heats at 0.15 °C/s at switch-on and cools at 1/250 s per °C of residual heat
        // once its fast heat has gone, up to 1/80 s right after switch-off (X; Y and Z a little
        // slower).
        switch_on_rate: [0.004, 0.0035, 0.003].map(|cooling_per_second| SwitchOnRate {
            heating_celsius_per_s: 0.15,
            cooling_per_second,
            cooling_per_second_per_remaining: 0.0085,
        }),
    };
    modified().with_extension(extension).unwrap()
}

/// Warm starts of axis `axis` at `ambient`: a unit switched on after a short off-time starts with
/// its element still cooling, below the cold start's initial bias by up to a few mdeg/s, more on
/// X than on Y, and above it on Z (the sign follows the axis's rate sensitivity).
fn warm_starts(axis: usize, ambient: f32) -> heapless::Vec<WarmStart, CURVES> {
    let per_celsius = [-0.0021, -0.0012, 0.0009][axis] * (1.0 + 0.02 * f64::from(ambient - 30.0));
    [0.4, 1.0, 2.0, 3.0]
        .iter()
        .map(|&heat: &f64| WarmStart {
            residual_heat_celsius: heat as f32,
            // Saturating as the element's rate does when the sensor's residual heat is large.
            bias_offset_dps: round_sig(per_celsius * 2.0 * (1.0 - (-heat / 2.0).exp())),
        })
        .collect()
}

/// The modified fixture (stage 3 keyed by rise, as the paper's) with the initial bias of warm
/// starts ([`warm_starts`]).
pub fn warm_started() -> FixtureTables {
    let mut tables = modified();
    for (a, axis) in tables.axes.iter_mut().enumerate() {
        for ambient in &mut axis.ambients {
            ambient.warm_starts = warm_starts(a, ambient.ambient_celsius);
        }
    }
    tables
}

/// The modified fixture with stage 3 keyed by heating history: curve `c` is the history that left
/// `0.2 · c` °C of residual heat at switch-on (a little more at warmer ambients, as a unit that
/// heats less there cools less too); X and Y also carry warm starts' initial bias, Z the paper's.
pub fn by_history() -> FixtureTables {
    let mut tables = warm_started();
    for ambient in &mut tables.axes[2].ambients {
        ambient.warm_starts.clear();
    }
    for axis in &mut tables.axes {
        for ambient in &mut axis.ambients {
            let scale = 1.0 + 0.01 * (ambient.ambient_celsius - 30.0);
            ambient.residual_heat_celsius = (0..CURVES)
                .map(|c| round5(0.2 * c as f64 * f64::from(scale)))
                .collect();
        }
    }
    tables
}

/// Capacities of the recommended fixture (the firmware's).
pub type FixtureRecommended = RecommendedTables<8, 3, 16>;

/// The recommended model: the modified fixture's curves with a turn-on bias fitted across
/// activations: a cubic of the switch-on temperature over 25–45 °C and a residual-heat slope of
/// a few mdeg/s per °C (negative on X and Y, positive on Z, as the warm starts' sign) over up to
/// 3 °C of residual heat.
pub fn recommended() -> FixtureRecommended {
    let turn_on = core::array::from_fn(|axis| {
        let (_, bias0, slope) = AXIS[axis];
        TurnOn {
            polynomial: PolynomialAxis {
                range_celsius: [25.0, 45.0],
                coefficients: heapless::Vec::from_slice(&[
                    round5(bias0 + slope * 5.0),
                    round5(slope * 10.0),
                    round5(0.0008),
                    round5(-0.0004),
                ])
                .unwrap(),
            },
            dps_per_residual_celsius: [-0.0021, -0.0012, 0.0009][axis],
            most_residual_heat_celsius: 3.0,
        }
    });
    RecommendedTables::try_new(&modified(), turn_on).unwrap()
}
