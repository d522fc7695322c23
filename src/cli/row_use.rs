//! Rows read onto the recording's grid: a grid much faster than the rows makes most samples up by
//! interpolation, one much slower leaves most rows unused (often a time column in another unit
//! than `--time-unit` says). Both are refused unless asked for.

use std::path::Path;

/// Grid rates suggested in messages, Hz (each divides 10⁹).
const GRID_RATES: [u32; 14] = [
    1000, 800, 500, 400, 250, 200, 125, 100, 50, 40, 25, 20, 10, 5,
];

/// How a file's rows became samples.
#[derive(Debug, Clone, Copy)]
pub struct RowUse<'a> {
    /// Rows read.
    pub rows: usize,
    /// Samples on the grid.
    pub samples: usize,
    /// The grid's rate, Hz.
    pub rate_hz: u32,
    /// `--time-unit` as given.
    pub time_unit: &'a str,
}

/// Refuses a grid on which more than 5 % of the samples are made up (unless `upsample`) or on
/// which fewer than half the rows are used (unless `downsample`), naming the file, the counts and
/// the flags that fix it.
pub fn refuse_made_up_or_dropped(
    file: &Path,
    use_: RowUse<'_>,
    upsample: bool,
    downsample: bool,
) -> anyhow::Result<()> {
    let RowUse {
        rows,
        samples,
        rate_hz,
        time_unit,
    } = use_;
    if rows < 2 || samples < 1 {
        return Ok(());
    }
    let seconds = samples as f64 / f64::from(rate_hz);
    let rows_hz = rows as f64 / seconds;
    let suggest = GRID_RATES
        .iter()
        .find(|&&r| f64::from(r) <= rows_hz * 1.05)
        .copied()
        .unwrap_or(1);
    if samples as f64 > rows as f64 * 1.05 && !upsample {
        anyhow::bail!(
            "{}: {rows} rows became {samples} samples at {rate_hz} Hz ({seconds:.1} s): {:.0} % of the samples would be made up by interpolation (the rows come at about {rows_hz:.1} per second); give `--rate-hz {suggest}`, or `--upsample` to interpolate anyway",
            file.display(),
            100.0 * (1.0 - rows as f64 / samples as f64)
        );
    }
    if (samples as f64) < rows as f64 * 0.5 && !downsample {
        let other = if time_unit == "ms" { "s" } else { "ms" };
        let faster = if suggest > rate_hz {
            format!("if the rows come faster than the grid, give `--rate-hz {suggest}`; ")
        } else {
            String::new()
        };
        anyhow::bail!(
            "{}: {rows} rows became {samples} samples at {rate_hz} Hz ({seconds:.3} s by the time column read in {time_unit}): {:.0} % of the rows would not be used. If the time column is in {other}, give `--time-unit {other}`; {faster}or `--downsample` to keep the grid's samples only",
            file.display(),
            100.0 * (1.0 - samples as f64 / rows as f64)
        );
    }
    Ok(())
}
