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
    /// Rows (or messages) read.
    pub rows: usize,
    /// What a row is, plural: `rows`, `sensor_gyro instance 0 messages`.
    pub what: &'a str,
    /// Samples on the grid.
    pub samples: usize,
    /// The grid's rate, Hz.
    pub rate_hz: u32,
    /// `--time-unit` as given, if the time column's unit is the user's to give.
    pub time_unit: Option<&'a str>,
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
        what,
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
            "{}: {rows} {what} became {samples} samples at {rate_hz} Hz ({seconds:.1} s): {:.0} % of the samples would be made up by interpolation (the {what} come at about {rows_hz:.1} per second); give `--rate-hz {suggest}`, or `--upsample` to interpolate anyway",
            file.display(),
            100.0 * (1.0 - rows as f64 / samples as f64)
        );
    }
    if (samples as f64) < rows as f64 * 0.5 && !downsample {
        let unit = time_unit.map_or(String::new(), |unit| {
            let other = if unit == "ms" { "s" } else { "ms" };
            format!(" If the time column is in {other}, give `--time-unit {other}`;")
        });
        let faster = if suggest > rate_hz {
            format!("if the rows come faster than the grid, give `--rate-hz {suggest}`; ")
        } else {
            String::new()
        };
        anyhow::bail!(
            "{}: {rows} {what} became {samples} samples at {rate_hz} Hz ({seconds:.3} s{}): {:.0} % of the {what} would not be used.{unit} {faster}or `--downsample` to keep the grid's samples only",
            file.display(),
            time_unit.map_or(String::new(), |u| format!(" by the time column read in {u}")),
            100.0 * (1.0 - samples as f64 / rows as f64)
        );
    }
    Ok(())
}
