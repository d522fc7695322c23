//! Validation errors that name the offending field and where it sits in the table.

use core::fmt;

/// `usize` to `u8`, saturating (capacities above 255 are documented as unsupported).
pub(crate) fn saturating_u8(value: usize) -> u8 {
    u8::try_from(value).unwrap_or(u8::MAX)
}

/// `usize` to `u16`, saturating.
pub(crate) fn saturating_u16(value: usize) -> u16 {
    u16::try_from(value).unwrap_or(u16::MAX)
}

/// Where in a table a bad value sits. Unused levels are `None`.
///
/// Displayed as a path such as `axes[1].ambients[0].curves[3].points[2].rise_celsius`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Location {
    /// Axis index (0 = X, 1 = Y, 2 = Z).
    pub axis: Option<u8>,
    /// Index into the calibration ambients of that axis.
    pub ambient: Option<u8>,
    /// Index into the heating-dynamics curves of that ambient.
    pub curve: Option<u8>,
    /// Index into that curve's points (one per reference time).
    pub point: Option<u8>,
    /// Index into the named field itself (a reference time, a coefficient, ...).
    pub index: Option<u16>,
}

impl Location {
    /// A location on one axis.
    pub fn axis(axis: usize) -> Self {
        Self {
            axis: Some(saturating_u8(axis)),
            ambient: None,
            curve: None,
            point: None,
            index: None,
        }
    }

    /// The same location, one level down: a calibration ambient.
    #[must_use]
    pub fn ambient(mut self, ambient: usize) -> Self {
        self.ambient = Some(saturating_u8(ambient));
        self
    }

    /// The same location, one level down: a heating-dynamics curve.
    #[must_use]
    pub fn curve(mut self, curve: usize) -> Self {
        self.curve = Some(saturating_u8(curve));
        self
    }

    /// The same location, one level down: a point of a curve.
    #[must_use]
    pub fn point(mut self, point: usize) -> Self {
        self.point = Some(saturating_u8(point));
        self
    }

    /// The same location, at an index of the named field.
    #[must_use]
    pub fn index(mut self, index: usize) -> Self {
        self.index = Some(saturating_u16(index));
        self
    }
}

/// What is wrong with a value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Problem {
    /// NaN or infinite.
    NonFinite,
    /// Not strictly greater than the value before it.
    NotIncreasing,
    /// Must be strictly positive.
    NotPositive,
    /// Must not be negative.
    Negative,
    /// The field has no entries but needs at least one.
    Empty,
    /// The field's length differs from the length it must match.
    LengthMismatch {
        /// Length the field must have.
        expected: u16,
        /// Length it has.
        found: u16,
    },
    /// An index that must be below a limit is not.
    OutOfRange {
        /// The first value that is too large.
        limit: u16,
    },
    /// Differs from an earlier entry it must equal.
    Mismatch,
    /// Larger in magnitude than any physical unit gives (a unit or sign slip, or a broken fit).
    Implausible {
        /// The largest plausible magnitude, in the field's unit.
        limit: u16,
    },
    /// A duration longer, at the stated sample rate, than the counter that holds it.
    TooManySamples {
        /// The most samples the counter holds.
        limit: u16,
    },
    /// A correlation beyond any gyro's, standing for a drift at its point (`k · rise`) larger
    /// than any gyro drifts.
    ImplausibleDrift {
        /// The largest plausible |k|, (°/s) per °C, and drift, °/s.
        limit: u16,
    },
}

/// A table or settings value failed validation.
///
/// Carries the field name, where it sits, and what is wrong, so a bench engineer can find it in the
/// JSON file or the fitter's output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Error {
    /// Name of the offending field, as spelled in the table type and its JSON.
    pub field: &'static str,
    /// Where the field sits.
    pub at: Location,
    /// What is wrong.
    pub problem: Problem,
}

impl Error {
    pub(crate) const fn new(field: &'static str, at: Location, problem: Problem) -> Self {
        Self { field, at, problem }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(axis) = self.at.axis {
            write!(f, "axes[{axis}].")?;
        }
        if let Some(ambient) = self.at.ambient {
            write!(f, "ambients[{ambient}].")?;
        }
        if let Some(curve) = self.at.curve {
            write!(f, "curves[{curve}].")?;
        }
        if let Some(point) = self.at.point {
            write!(f, "points[{point}].")?;
        }
        f.write_str(self.field)?;
        if let Some(index) = self.at.index {
            write!(f, "[{index}]")?;
        }
        match self.problem {
            Problem::NonFinite => f.write_str(": value is NaN or infinite"),
            Problem::NotIncreasing => f.write_str(": not strictly greater than the previous value"),
            Problem::NotPositive => f.write_str(": must be greater than zero"),
            Problem::Negative => f.write_str(": must not be negative"),
            Problem::Empty => f.write_str(": needs at least one entry"),
            Problem::LengthMismatch { expected, found } => {
                write!(f, ": has {found} entries, expected {expected}")
            }
            Problem::OutOfRange { limit } => write!(f, ": must be less than {limit}"),
            Problem::Mismatch => f.write_str(": differs from the earlier entry it must equal"),
            Problem::Implausible { limit } => {
                write!(f, ": magnitude beyond {limit}, implausible for a gyro")
            }
            Problem::TooManySamples { limit } => {
                write!(f, ": more than {limit} samples at the sample rate given")
            }
            Problem::ImplausibleDrift { limit } => {
                write!(
                    f,
                    ": beyond {limit} (°/s)/°C for a drift k × rise beyond {limit} °/s, implausible for a gyro"
                )
            }
        }
    }
}

impl core::error::Error for Error {}

/// Checks that every value is finite and strictly increasing; names the first offender.
pub(crate) fn check_increasing(
    field: &'static str,
    at: Location,
    values: impl IntoIterator<Item = f32>,
) -> Result<(), Error> {
    let mut previous = f32::NEG_INFINITY;
    for (index, value) in values.into_iter().enumerate() {
        if !value.is_finite() {
            return Err(Error::new(field, at.index(index), Problem::NonFinite));
        }
        if value <= previous {
            return Err(Error::new(field, at.index(index), Problem::NotIncreasing));
        }
        previous = value;
    }
    Ok(())
}

/// Checks that every value is finite; names the first offender.
pub(crate) fn check_finite(
    field: &'static str,
    at: Location,
    values: impl IntoIterator<Item = f32>,
) -> Result<(), Error> {
    match values.into_iter().position(|v| !v.is_finite()) {
        Some(index) => Err(Error::new(field, at.index(index), Problem::NonFinite)),
        None => Ok(()),
    }
}

/// Checks a length against the length it must match.
pub(crate) fn check_len(
    field: &'static str,
    at: Location,
    expected: usize,
    found: usize,
) -> Result<(), Error> {
    if expected == found {
        Ok(())
    } else {
        Err(Error::new(
            field,
            at,
            Problem::LengthMismatch {
                expected: saturating_u16(expected),
                found: saturating_u16(found),
            },
        ))
    }
}
