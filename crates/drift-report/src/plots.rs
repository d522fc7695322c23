//! Line and point charts as SVG (plotters' SVG backend: no fonts or system libraries needed).

use anyhow::anyhow;
use plotters::prelude::*;

/// One named series of (x, y) points.
pub struct Series {
    /// Legend label.
    pub name: String,
    /// Points, in drawing order.
    pub points: Vec<(f64, f64)>,
    /// Draw markers only (no connecting line).
    pub markers_only: bool,
}

impl Series {
    /// A line series.
    pub fn line(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            markers_only: false,
        }
    }

    /// A marker series.
    pub fn markers(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            markers_only: true,
        }
    }
}

/// A chart's labels.
pub struct Chart<'a> {
    /// Title above the chart.
    pub title: &'a str,
    /// X axis label.
    pub x: &'a str,
    /// Y axis label.
    pub y: &'a str,
}

fn bounds(series: &[Series], pick: impl Fn(&(f64, f64)) -> f64) -> (f64, f64) {
    let (lo, hi) = series
        .iter()
        .flat_map(|s| s.points.iter())
        .map(pick)
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-9);
    (lo - pad, hi + pad)
}

/// Draws `series` as an SVG document.
pub fn draw(chart: &Chart<'_>, series: &[Series]) -> anyhow::Result<String> {
    let mut svg = String::new();
    draw_into(&mut svg, chart, series)?;
    Ok(svg)
}

/// Decimals that tell ticks apart over `lo…hi` (about ten ticks), no more: `0.015` on a 0.03
/// range, `4.4` on a 4-degree one, `10` on a count.
fn decimals(lo: f64, hi: f64) -> usize {
    let span = (hi - lo).abs();
    if !(span.is_finite() && span > 0.0) {
        return 0;
    }
    // Ticks sit ~span/10 apart: one significant digit of that step.
    let digits = (-(span / 10.0).log10()).ceil();
    digits.clamp(0.0, 9.0) as usize
}

/// A tick label with `decimals` decimals; a value that rounds to zero reads "0", never "-0.000".
pub(crate) fn tick(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    if text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        "0".to_owned()
    } else {
        text
    }
}

/// Width of the plot; the legend gets a column to its right, off the data.
const PLOT_WIDTH: u32 = 900;
/// Width of the legend column.
const LEGEND_WIDTH: u32 = 260;
/// Height of the figure.
const HEIGHT: u32 = 520;

fn draw_into(svg: &mut String, chart: &Chart<'_>, series: &[Series]) -> anyhow::Result<()> {
    let fail = |e: &dyn std::fmt::Display| anyhow!("drawing \"{}\": {e}", chart.title);
    let (x0, x1) = bounds(series, |p| p.0);
    let (y0, y1) = bounds(series, |p| p.1);
    let (x_decimals, y_decimals) = (decimals(x0, x1), decimals(y0, y1));
    let root =
        SVGBackend::with_string(svg, (PLOT_WIDTH + LEGEND_WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let (left, legend) = root.split_horizontally(PLOT_WIDTH);
    let mut plot = ChartBuilder::on(&left)
        .caption(chart.title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| fail(&e))?;
    plot.configure_mesh()
        .x_desc(chart.x)
        .y_desc(chart.y)
        .x_label_formatter(&|v| tick(*v, x_decimals))
        .y_label_formatter(&|v| tick(*v, y_decimals))
        .draw()
        .map_err(|e| fail(&e))?;
    let text = ("sans-serif", 14).into_font().color(&BLACK);
    for (index, s) in series.iter().enumerate() {
        let color = Palette99::pick(index).to_rgba();
        if s.markers_only {
            plot.draw_series(s.points.iter().map(|&p| Circle::new(p, 3, color.filled())))
                .map_err(|e| fail(&e))?;
        } else {
            plot.draw_series(LineSeries::new(
                s.points.iter().copied(),
                color.stroke_width(2),
            ))
            .map_err(|e| fail(&e))?;
        }
        // The legend, in its own column beside the plot: it never covers a point.
        let y = 48 + 22 * index as i32;
        if s.markers_only {
            legend
                .draw(&Circle::new((18, y), 4, color.filled()))
                .map_err(|e| fail(&e))?;
        } else {
            legend
                .draw(&PathElement::new(
                    vec![(6, y), (30, y)],
                    color.stroke_width(2),
                ))
                .map_err(|e| fail(&e))?;
        }
        legend
            .draw(&Text::new(s.name.clone(), (38, y - 8), text.clone()))
            .map_err(|e| fail(&e))?;
    }
    root.present().map_err(|e| fail(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_carry_the_decimals_their_spacing_needs() {
        assert_eq!(decimals(0.0, 0.03), 3);
        assert_eq!(decimals(2.0, 6.4), 1);
        assert_eq!(decimals(0.0, 40.0), 0);
        assert_eq!(decimals(1.0, 1.0), 0);
    }

    #[test]
    fn a_tick_at_zero_reads_0_whatever_its_sign_or_decimals() {
        assert_eq!(tick(-0.00004, 3), "0");
        assert_eq!(tick(0.0, 2), "0");
        assert_eq!(tick(-0.0, 0), "0");
        assert_eq!(tick(-0.0015, 3), "-0.002");
        assert_eq!(tick(0.25, 2), "0.25");
        assert_eq!(tick(10.0, 0), "10");
    }
}
