//! numpy arguments: dtype, shape and emptiness checks with messages that name the argument, and
//! row access that borrows the caller's memory (no copy of the array, whatever its layout).

use numpy::ndarray::{ArrayView1, ArrayView2, Axis, Slice};
use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadwriteArray2,
    PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use crate::errors::Error;

/// What an argument is, for error messages: `int64 array of shape (5, 2)` or `list`.
pub fn describe(value: &Bound<'_, PyAny>) -> String {
    match value.cast::<PyUntypedArray>() {
        Ok(array) => {
            let dtype = array
                .dtype()
                .str()
                .map_or_else(|_| "unknown dtype".to_owned(), |s| s.to_string());
            format!("{dtype} array of shape {}", shape_text(array.shape()))
        }
        Err(_) => value
            .get_type()
            .name()
            .map_or_else(|_| "an object".to_owned(), |name| name.to_string()),
    }
}

/// A shape as Python prints it: `(5,)`, `(5, 2)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [single] => format!("({single},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(ToString::to_string).collect();
            format!("({})", parts.join(", "))
        }
    }
}

fn not_empty(name: &str, value: &Bound<'_, PyAny>, rows: usize) -> Result<(), Error> {
    if rows == 0 {
        return Err(Error::Input(format!(
            "`{name}` must not be empty, got {}",
            describe(value)
        )));
    }
    Ok(())
}

/// The kind of a numpy array's dtype (`'f'`, `'m'` for timedelta64, ...), if `value` is one.
fn dtype_kind(value: &Bound<'_, PyAny>) -> Option<char> {
    let array = value.cast::<PyUntypedArray>().ok()?;
    let kind = array
        .dtype()
        .getattr("kind")
        .ok()?
        .extract::<String>()
        .ok()?;
    kind.chars().next()
}

/// Whether `value` is a pandas object (a Series or a DataFrame), which is not an ndarray.
fn is_pandas(value: &Bound<'_, PyAny>) -> bool {
    value
        .get_type()
        .module()
        .is_ok_and(|m| m.to_string().starts_with("pandas"))
}

/// How to convert `value` into what `expected` needs, for the error message.
fn hint(value: &Bound<'_, PyAny>, milliseconds: bool) -> &'static str {
    if is_pandas(value) {
        return "a pandas object: pass .to_numpy() of the column(s), then convert as needed";
    }
    match (dtype_kind(value), milliseconds) {
        (Some('m'), true) => {
            "timedelta64: convert with (t // np.timedelta64(1, 'ms')).astype(np.uint32); .astype(np.uint32) would count its native unit"
        }
        (Some('f'), false) => {
            "temperatures in °C? convert with np.round(settings.raw(celsius)).astype(np.int16); .astype(np.int16) would truncate °C to whole degrees"
        }
        (_, true) => "convert with .astype(np.uint32)",
        (_, false) => "convert with .astype(np.int16)",
    }
}

/// A borrowed `(n,)` uint32 array (times since switch-on, ms).
pub fn times<'py>(
    name: &str,
    value: &Bound<'py, PyAny>,
) -> Result<PyReadonlyArray1<'py, u32>, Error> {
    let array = value.cast::<PyArray1<u32>>().map_err(|_| {
        Error::Input(format!(
            "`{name}` must be a uint32 array of shape (n,), got {} ({})",
            describe(value),
            hint(value, true)
        ))
    })?;
    not_empty(name, value, array.len())?;
    array
        .try_readonly()
        .map_err(|error| Error::Input(format!("`{name}` cannot be borrowed: {error}")))
}

/// A borrowed `(n, columns)` float array (rates or raw temperatures: 3 columns; auxiliary inputs:
/// 4), float32 or float64.
pub enum Rows<'py> {
    /// float32: read in place.
    F32(PyReadonlyArray2<'py, f32>),
    /// float64: read in place, rounded to f32 per value (as `astype(np.float32)` does).
    F64(PyReadonlyArray2<'py, f64>),
    /// int16 (raw temperature readings as recordings hold them): exact in f32.
    I16(PyReadonlyArray2<'py, i16>),
}

impl<'py> Rows<'py> {
    /// Checks and borrows an `(n, 3)` `value`, naming it `name` in errors.
    pub fn borrow(name: &str, value: &Bound<'py, PyAny>) -> Result<Self, Error> {
        Self::borrow_columns(name, value, 3)
    }

    /// Checks and borrows `(n, 3)` raw temperatures: float32, float64, or int16 as
    /// `Segment.temperature_raw` returns them.
    pub fn borrow_temperatures(name: &str, value: &Bound<'py, PyAny>) -> Result<Self, Error> {
        let Ok(array) = value.cast::<PyArray2<i16>>() else {
            // A float array of the right shape keeps its own error (empty, not borrowable); any
            // other value is told every dtype it may have.
            let columns = |shape: &[usize]| shape.get(1) == Some(&3);
            let float_rows = value
                .cast::<PyArray2<f32>>()
                .is_ok_and(|a| columns(a.shape()))
                || value
                    .cast::<PyArray2<f64>>()
                    .is_ok_and(|a| columns(a.shape()));
            return Self::borrow_columns(name, value, 3).map_err(|error| {
                if float_rows {
                    error
                } else {
                    Error::Input(format!(
                        "`{name}` must be a float32, float64 or int16 array of shape (n, 3), got {}",
                        describe(value)
                    ))
                }
            });
        };
        if array.shape().get(1) != Some(&3) {
            return Err(Error::Input(format!(
                "`{name}` must be a float32, float64 or int16 array of shape (n, 3), got {}",
                describe(value)
            )));
        }
        not_empty(name, value, array.shape().first().copied().unwrap_or(0))?;
        array
            .try_readonly()
            .map(Self::I16)
            .map_err(|error| Error::Input(format!("`{name}` cannot be borrowed: {error}")))
    }

    /// Checks and borrows an `(n, columns)` `value`, naming it `name` in errors.
    pub fn borrow_columns(
        name: &str,
        value: &Bound<'py, PyAny>,
        columns: usize,
    ) -> Result<Self, Error> {
        let wrong = || {
            Error::Input(format!(
                "`{name}` must be a float32 or float64 array of shape (n, {columns}), got {}",
                describe(value)
            ))
        };
        let borrow_error = |error: numpy::BorrowError| {
            Error::Input(format!("`{name}` cannot be borrowed: {error}"))
        };
        let rows = if let Ok(array) = value.cast::<PyArray2<f32>>() {
            Self::F32(array.try_readonly().map_err(borrow_error)?)
        } else if let Ok(array) = value.cast::<PyArray2<f64>>() {
            Self::F64(array.try_readonly().map_err(borrow_error)?)
        } else {
            return Err(wrong());
        };
        let (n, found) = {
            let view = rows.view();
            (view.len(), view.shape().get(1).copied())
        };
        if found != Some(columns) {
            return Err(wrong());
        }
        not_empty(name, value, n)?;
        Ok(rows)
    }

    /// A view that can cross into `Python::detach` (no Python object inside).
    pub fn view(&self) -> RowsView<'_> {
        match self {
            Self::F32(array) => RowsView::F32(array.as_array()),
            Self::F64(array) => RowsView::F64(array.as_array()),
            Self::I16(array) => RowsView::I16(array.as_array()),
        }
    }
}

/// Rows of an `(n, columns)` array of either float dtype, any strides.
pub enum RowsView<'a> {
    /// float32 rows.
    F32(ArrayView2<'a, f32>),
    /// float64 rows.
    F64(ArrayView2<'a, f64>),
    /// int16 rows (raw temperatures).
    I16(ArrayView2<'a, i16>),
}

impl RowsView<'_> {
    /// The array's shape, `[n, columns]`.
    pub fn shape(&self) -> &[usize] {
        match self {
            Self::F32(view) => view.shape(),
            Self::F64(view) => view.shape(),
            Self::I16(view) => view.shape(),
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.shape().first().copied().unwrap_or(0)
    }

    /// Copies rows `start..` as f32 into `out`, as many as `out` yields (`N`: the column count).
    pub fn copy_rows<'o, const N: usize>(
        &self,
        start: usize,
        out: impl Iterator<Item = &'o mut [f32; N]>,
    ) {
        match self {
            Self::F32(view) => copy_rows(view, start, out),
            Self::F64(view) => copy_rows(view, start, out),
            Self::I16(view) => copy_rows(view, start, out),
        }
    }
}

/// An element type read as f32.
trait AsF32: Copy {
    fn as_f32(self) -> f32;
}

impl AsF32 for f32 {
    fn as_f32(self) -> f32 {
        self
    }
}

impl AsF32 for i16 {
    fn as_f32(self) -> f32 {
        f32::from(self)
    }
}

impl AsF32 for f64 {
    /// Round to nearest, ties to even: the same f32 as numpy's `astype(np.float32)`.
    fn as_f32(self) -> f32 {
        self as f32
    }
}

fn copy_rows<'o, T: AsF32, const N: usize>(
    view: &ArrayView2<'_, T>,
    start: usize,
    out: impl Iterator<Item = &'o mut [f32; N]>,
) {
    if let Some(flat) = view.as_slice() {
        // C-contiguous: straight from the caller's buffer.
        let rows = flat.get(start.saturating_mul(N)..).unwrap_or_default();
        for (dst, src) in out.zip(rows.chunks_exact(N)) {
            for (d, s) in dst.iter_mut().zip(src) {
                *d = s.as_f32();
            }
        }
    } else if start < view.nrows() {
        // Any other layout (a column slice, a transposed or reversed array): through the strides.
        let rows = view.slice_axis(Axis(0), Slice::from(start..));
        for (dst, src) in out.zip(rows.rows()) {
            for (d, s) in dst.iter_mut().zip(src) {
                *d = s.as_f32();
            }
        }
    }
}

/// Times from a uint32 view, any stride, starting at `start`.
pub fn copy_times<'o>(
    view: &ArrayView1<'_, u32>,
    start: usize,
    out: impl Iterator<Item = &'o mut u32>,
) {
    if let Some(times) = view.as_slice() {
        // Contiguous: a plain copy from the caller's buffer rather than ndarray's strided iterator.
        for (d, s) in out.zip(times.get(start..).unwrap_or_default()) {
            *d = *s;
        }
    } else if start < view.len() {
        let rest = view.slice_axis(Axis(0), Slice::from(start..));
        for (d, s) in out.zip(rest.iter()) {
            *d = *s;
        }
    }
}

/// `correct_batch`'s outputs: corrected (n, 3) float32, bias (n, 3) float32, flags (n, 3) uint16.
pub type BatchArrays<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<u16>>,
);

/// The caller's output arrays for `correct_batch(..., out=(corrected, bias, flags))`: C-contiguous,
/// writeable, `(n, 3)` float32, float32 and uint16, none of them an input or each other.
pub struct OutArrays<'py> {
    /// The arrays, to hand back to the caller.
    pub arrays: BatchArrays<'py>,
    /// Exclusive borrows of them (rust-numpy refuses overlap with the inputs' borrows).
    pub corrected: PyReadwriteArray2<'py, f32>,
    /// See `corrected`.
    pub bias: PyReadwriteArray2<'py, f32>,
    /// See `corrected`.
    pub flags: PyReadwriteArray2<'py, u16>,
}

fn out_array<'py, T: numpy::Element>(
    name: &str,
    dtype: &str,
    value: &Bound<'py, PyAny>,
    n: usize,
) -> Result<Bound<'py, PyArray2<T>>, Error> {
    let wrong = || {
        Error::Input(format!(
            "`{name}` must be a writeable C-contiguous {dtype} array of shape ({n}, 3), got {}",
            describe(value)
        ))
    };
    let array = value.cast::<PyArray2<T>>().map_err(|_| wrong())?;
    if array.shape() != [n, 3] || !array.is_c_contiguous() {
        return Err(wrong());
    }
    Ok(array.clone())
}

impl<'py> OutArrays<'py> {
    /// Checks and borrows `out` for `n` samples.
    pub fn borrow(out: &Bound<'py, PyAny>, n: usize) -> Result<Self, Error> {
        let (corrected, bias, flags) = out
            .extract::<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)>()
            .map_err(|_| {
                Error::Input(format!(
                    "`out` must be a tuple of 3 arrays (corrected_dps, bias_dps, flags), got {}",
                    describe(out)
                ))
            })?;
        let arrays = (
            out_array::<f32>("out[0]", "float32", &corrected, n)?,
            out_array::<f32>("out[1]", "float32", &bias, n)?,
            out_array::<u16>("out[2]", "uint16", &flags, n)?,
        );
        let exclusive = |name: &str, error: numpy::BorrowError| {
            Error::Input(format!(
                "`{name}` must be writeable and not also an input or another output: {error}"
            ))
        };
        Ok(Self {
            corrected: arrays
                .0
                .try_readwrite()
                .map_err(|e| exclusive("out[0]", e))?,
            bias: arrays
                .1
                .try_readwrite()
                .map_err(|e| exclusive("out[1]", e))?,
            flags: arrays
                .2
                .try_readwrite()
                .map_err(|e| exclusive("out[2]", e))?,
            arrays,
        })
    }
}

impl RowsView<'_> {
    /// The first (row, column) holding NaN or ±inf, if any.
    pub fn first_non_finite(&self) -> Option<(usize, usize)> {
        fn find<T: AsF32>(view: &ArrayView2<'_, T>) -> Option<(usize, usize)> {
            view.indexed_iter()
                .find(|(_, v)| !v.as_f32().is_finite())
                .map(|(index, _)| index)
        }
        match self {
            Self::F32(view) => find(view),
            Self::F64(view) => find(view),
            Self::I16(_) => None,
        }
    }

    /// Column `axis` as f32 values (rounded per value, as `astype(np.float32)` does).
    pub fn column(&self, axis: usize) -> Vec<f32> {
        match self {
            Self::F32(view) => view.column(axis).to_vec(),
            Self::F64(view) => view.column(axis).iter().map(|v| v.as_f32()).collect(),
            Self::I16(view) => view.column(axis).iter().map(|v| v.as_f32()).collect(),
        }
    }
}

/// A borrowed, non-empty `(n, 3)` int16 array (raw temperature readings), any strides.
pub fn raw_rows<'py>(
    name: &str,
    value: &Bound<'py, PyAny>,
) -> Result<PyReadonlyArray2<'py, i16>, Error> {
    let wrong = || {
        Error::Input(format!(
            "`{name}` must be an int16 array of shape (n, 3), got {} ({})",
            describe(value),
            hint(value, false)
        ))
    };
    let array = value.cast::<PyArray2<i16>>().map_err(|_| wrong())?;
    if array.shape().get(1) != Some(&3) {
        return Err(wrong());
    }
    not_empty(name, value, array.shape().first().copied().unwrap_or(0))?;
    array
        .try_readonly()
        .map_err(|error| Error::Input(format!("`{name}` cannot be borrowed: {error}")))
}

/// A 1-D float32 or float64 array of finite values, as f32 (may be empty).
pub fn finite_values(name: &str, value: &Bound<'_, PyAny>) -> Result<Vec<f32>, Error> {
    finite_1d(name, value, |v| v, AsF32::as_f32)
}

/// A 1-D float32 or float64 array of finite values, as f64 (may be empty): for statistics over
/// results, which need not be rounded to the corrector's f32.
pub fn finite_values_f64(name: &str, value: &Bound<'_, PyAny>) -> Result<Vec<f64>, Error> {
    finite_1d(name, value, f64::from, |v| v)
}

/// A 1-D float32 or float64 array, each value converted by `from_f32` or `from_f64`, then checked
/// finite (after the conversion: a float64 beyond f32's range is not finite as f32).
fn finite_1d<T: Copy + Into<f64> + std::fmt::Display>(
    name: &str,
    value: &Bound<'_, PyAny>,
    from_f32: impl Fn(f32) -> T,
    from_f64: impl Fn(f64) -> T,
) -> Result<Vec<T>, Error> {
    // Any layout: a column of a 2-D array or a strided view is copied through its strides.
    let values: Vec<T> = if let Ok(array) = value.cast::<PyArray1<f32>>() {
        let view = array.try_readonly().map_err(|e| borrow_error(name, e))?;
        view.as_array().iter().copied().map(from_f32).collect()
    } else if let Ok(array) = value.cast::<PyArray1<f64>>() {
        let view = array.try_readonly().map_err(|e| borrow_error(name, e))?;
        view.as_array().iter().copied().map(from_f64).collect()
    } else {
        return Err(Error::Input(format!(
            "`{name}` must be a float32 or float64 array of shape (n,), got {}",
            describe(value)
        )));
    };
    if let Some((i, v)) = values
        .iter()
        .enumerate()
        .find(|(_, v)| !(**v).into().is_finite())
    {
        return Err(Error::Input(format!(
            "`{name}` must be finite, got {v} at index {i}"
        )));
    }
    Ok(values)
}

fn borrow_error(name: &str, error: impl std::fmt::Display) -> Error {
    Error::Input(format!("`{name}` cannot be read: {error}"))
}

/// A `(3, N)` float32 or float64 array (or nested sequence): `N` numbers per axis X, Y, Z.
/// `shape` says in the error message what the numbers are.
pub fn rows_per_axis<const N: usize>(
    name: &str,
    shape: &str,
    value: &Bound<'_, PyAny>,
) -> Result<[[f64; N]; 3], Error> {
    fn read<T: Copy + Into<f64>, const N: usize>(
        view: &ArrayView2<'_, T>,
    ) -> Option<[[f64; N]; 3]> {
        if view.shape() != [3, N] {
            return None;
        }
        let mut rows = [[0.0; N]; 3];
        for (r, row) in rows.iter_mut().enumerate() {
            for (c, value) in row.iter_mut().enumerate() {
                *value = (*view.get((r, c))?).into();
            }
        }
        Some(rows)
    }
    let wrong = || Error::Input(format!("`{name}` must be {shape}, got {}", describe(value)));
    let borrow_error = |error| Error::Input(format!("`{name}` cannot be borrowed: {error}"));
    if let Ok(array) = value.cast::<PyArray2<f32>>() {
        let array = array.try_readonly().map_err(borrow_error)?;
        read(&array.as_array()).ok_or_else(wrong)
    } else if let Ok(array) = value.cast::<PyArray2<f64>>() {
        let array = array.try_readonly().map_err(borrow_error)?;
        read(&array.as_array()).ok_or_else(wrong)
    } else if value.cast::<PyUntypedArray>().is_ok() {
        // Another dtype or number of dimensions: not read through Python's sequence protocol.
        Err(wrong())
    } else {
        value.extract::<[[f64; N]; 3]>().map_err(|_| wrong())
    }
}
