//! The report's coverage map: the calibration's switch-on temperatures × residual heats with the
//! number of calibration activations behind each cell (an SVG per unit), the envelope the
//! corrector flags, and how much held-out data fell outside it.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::anyhow;
use drift_evaluate::coverage::{
    Outside, UnitCoverage, RESIDUAL_HEAT_CELL_CELSIUS, SWITCH_ON_CELL_CELSIUS,
};
use plotters::prelude::*;

use crate::write_atomic;

const WIDTH: u32 = 900;
const HEIGHT: u32 = 520;

fn percent(part: usize, whole: usize) -> String {
    if whole == 0 {
        "–".into()
    } else {
        format!("{:.1} %", 100.0 * part as f64 / whole as f64)
    }
}

/// The envelope every axis shares: the intersection of the axes' rectangles (°C), with their
/// margin. (lowest switch-on, highest switch-on, most residual heat.)
fn shared_envelope(unit: &UnitCoverage) -> (f64, f64, f64) {
    unit.envelope
        .iter()
        .map(|e| {
            (
                f64::from(e.switch_on_celsius[0] - e.margin_celsius),
                f64::from(e.switch_on_celsius[1] + e.margin_celsius),
                f64::from(e.most_residual_heat_celsius),
            )
        })
        .fold(
            (f64::NEG_INFINITY, f64::INFINITY, f64::INFINITY),
            |(lo, hi, heat), (l, h, m)| (lo.max(l), hi.min(h), heat.min(m)),
        )
}

/// The map of one unit as an SVG document: calibration cells shaded by their activation count
/// (the count written in each), cells with held-out activations only outlined, the envelope
/// dashed.
pub fn draw_map(unit: &UnitCoverage) -> anyhow::Result<String> {
    let title = format!(
        "{}: calibration activations per switch-on temperature × residual heat",
        unit.unit_id
    );
    let fail = |e: &dyn std::fmt::Display| anyhow!("drawing \"{title}\": {e}");
    let (lo, hi, most) = shared_envelope(unit);
    let x0 = unit
        .cells
        .iter()
        .map(|c| c.switch_on_celsius)
        .chain([lo])
        .filter(|v| v.is_finite())
        .fold(f64::INFINITY, f64::min);
    let x1 = unit
        .cells
        .iter()
        .map(|c| c.switch_on_celsius + SWITCH_ON_CELL_CELSIUS)
        .chain([hi])
        .filter(|v| v.is_finite())
        .fold(f64::NEG_INFINITY, f64::max);
    let y1 = unit
        .cells
        .iter()
        .map(|c| c.residual_heat_celsius + RESIDUAL_HEAT_CELL_CELSIUS)
        .chain([most])
        .filter(|v| v.is_finite())
        .fold(RESIDUAL_HEAT_CELL_CELSIUS, f64::max);
    let (x0, x1) = if x0 < x1 { (x0, x1) } else { (0.0, 1.0) };
    let most_count = unit
        .cells
        .iter()
        .map(|c| c.calibration_activations)
        .max()
        .unwrap_or(0)
        .max(1);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let mut plot = ChartBuilder::on(&root)
            .caption(&title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, 0.0..y1)
            .map_err(|e| fail(&e))?;
        plot.configure_mesh()
            .disable_mesh()
            .x_desc("switch-on temperature, °C (mean over axes)")
            .y_desc("residual heat at switch-on, °C")
            .x_label_formatter(&|v| crate::plots::tick(*v, 1))
            .y_label_formatter(&|v| crate::plots::tick(*v, 1))
            .draw()
            .map_err(|e| fail(&e))?;
        let text = ("sans-serif", 12).into_font().color(&BLACK);
        for cell in &unit.cells {
            let corner = (cell.switch_on_celsius, cell.residual_heat_celsius);
            let far = (
                corner.0 + SWITCH_ON_CELL_CELSIUS,
                corner.1 + RESIDUAL_HEAT_CELL_CELSIUS,
            );
            if cell.calibration_activations > 0 {
                let shade = 0.15 + 0.75 * cell.calibration_activations as f64 / most_count as f64;
                plot.draw_series([Rectangle::new([corner, far], BLUE.mix(shade).filled())])
                    .map_err(|e| fail(&e))?;
                plot.draw_series([Text::new(
                    cell.calibration_activations.to_string(),
                    (corner.0 + 0.1 * SWITCH_ON_CELL_CELSIUS, far.1 - 0.15),
                    text.clone(),
                )])
                .map_err(|e| fail(&e))?;
            }
            if cell.held_out_activations > 0 {
                plot.draw_series([Rectangle::new([corner, far], RED.stroke_width(1))])
                    .map_err(|e| fail(&e))?;
            }
        }
        if lo.is_finite() && hi.is_finite() && most.is_finite() && lo < hi {
            let edge = [(lo, 0.0), (hi, 0.0), (hi, most), (lo, most), (lo, 0.0)];
            plot.draw_series(DashedLineSeries::new(edge, 6, 4, BLACK.stroke_width(2)))
                .map_err(|e| fail(&e))?;
        }
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(svg)
}

fn outside_row(md: &mut String, unit: &str, o: &Outside) {
    let _ = writeln!(
        md,
        "| {unit} | {} | {} | {} | {} | {} of {} |",
        o.split,
        o.axis_activations,
        percent(o.axis_activations_outside, o.axis_activations),
        percent(o.samples_outside, o.samples),
        o.activations_in_empty_cells,
        o.activations
    );
}

/// Writes each unit's map (`fig-coverage-<unit>.svg`) into `dir` and returns the section
/// (Markdown); empty without units.
pub fn section(dir: &Path, units: &[UnitCoverage]) -> anyhow::Result<String> {
    if units.is_empty() {
        return Ok(String::new());
    }
    let mut md = String::new();
    writeln!(md, "## Coverage of the calibration\n")?;
    writeln!(
        md,
        "Where the recommended model's tables are valid: the calibration activations its turn-on \
         bias was fitted on, per cell of {SWITCH_ON_CELL_CELSIUS} °C of switch-on temperature × \
         {RESIDUAL_HEAT_CELL_CELSIUS} °C of residual heat (what firmware estimates at switch-on; \
         each activation at its axes' mean). The envelope (dashed) is what the corrector flags \
         per axis at switch-on: a switch-on temperature beyond the calibration's by more than the \
         ambient margin (`TEMPERATURE_OUT_OF_RANGE`) or more residual heat than the calibration \
         had (`HISTORY_OUT_OF_SPAN`). Red outlines: cells with held-out activations. \
         `coverage.json` holds every cell.\n"
    )?;
    for unit in units {
        let name = format!("fig-coverage-{}.svg", unit.unit_id);
        let svg = draw_map(unit)?;
        write_atomic(&dir.join(&name), svg.as_bytes())?;
        let caption = format!(
            "{}: {} calibration activations per switch-on temperature × residual heat; dashed: \
             the envelope",
            unit.unit_id, unit.calibration_activations
        );
        writeln!(md, "![{caption}]({name})\n\n*{caption}*\n")?;
    }
    writeln!(
        md,
        "Held-out data outside the envelope (an activation outside on an axis counts with all \
         its residual samples, every 100 ms), and activations inside it on every axis but in a \
         cell without calibration activations:\n"
    )?;
    writeln!(
        md,
        "| unit | data | activations × axes | outside (activations × axes) | outside (samples) | in empty cells (activations) |\n|---|---|---:|---:|---:|---:|"
    )?;
    for unit in units {
        for o in &unit.outside {
            outside_row(&mut md, &unit.unit_id, o);
        }
    }
    md.push('\n');
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;
    use drift_evaluate::coverage::{Cell, Envelope};

    fn unit() -> UnitCoverage {
        let envelope = Envelope {
            switch_on_celsius: [30.0, 44.0],
            margin_celsius: 0.5,
            most_residual_heat_celsius: 6.0,
        };
        UnitCoverage {
            unit_id: "GIU-01".into(),
            envelope: [envelope; 3],
            calibration_activations: 7,
            cells: vec![
                Cell {
                    switch_on_celsius: 30.0,
                    residual_heat_celsius: 0.0,
                    calibration_activations: 5,
                    held_out_activations: 0,
                },
                Cell {
                    switch_on_celsius: 42.0,
                    residual_heat_celsius: 5.0,
                    calibration_activations: 2,
                    held_out_activations: 3,
                },
            ],
            outside: vec![Outside {
                split: "field",
                axis_activations: 9,
                axis_activations_outside: 3,
                samples: 900,
                samples_outside: 300,
                activations_in_empty_cells: 1,
                activations: 3,
            }],
        }
    }

    #[test]
    fn the_map_writes_each_count_and_the_envelope() {
        let svg = draw_map(&unit()).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..40]);
        assert!(
            svg.contains("\n5\n</text>") && svg.contains("\n2\n</text>"),
            "each calibration cell's count is written"
        );
        assert_eq!(
            svg.matches("stroke=\"#FF0000\"").count(),
            1,
            "one held-out cell"
        );
        assert!(
            svg.matches("stroke-width=\"2\"").count() >= 4,
            "the envelope's four dashed edges"
        );
    }

    #[test]
    fn the_section_says_the_share_outside() {
        let dir = std::env::temp_dir().join(format!("coverage-section-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let md = section(&dir, &[unit()]).unwrap();
        assert!(dir.join("fig-coverage-GIU-01.svg").is_file());
        assert!(
            md.contains("| GIU-01 | field | 9 | 33.3 % | 33.3 % | 1 of 3 |"),
            "{md}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(section(&dir, &[]).unwrap(), "");
    }
}
