//! `gyrodrift.StillnessLearner`: drift-core's run-time offset learner, one sample or a batch.

use drift_core::{StillnessLearner, StillnessSettings};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::args::per_axis;
use crate::arrays::Rows;
use crate::errors::Error;
use numpy::ndarray::Array2;

/// Learns the rate's offset while the instrument stands still (x-io Fusion's offset correction
/// with rate and acceleration variance tests); feed it the tables' corrected rate to learn what
/// they left.
#[pyclass(module = "gyrodrift", name = "StillnessLearner")]
#[derive(Debug)]
pub struct PyStillnessLearner {
    learner: StillnessLearner,
    settings: StillnessSettings,
}

/// `update_batch`'s result: rates less the offset `(n, 3)`, still `(n,)`, learning `(n,)`.
type Learned<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<bool>>,
);

/// `update`'s result: the rate less the offset, still, learning.
type Learned1 = ((f32, f32, f32), bool, bool);

fn rows(rows: &Rows<'_>) -> Vec<[f32; 3]> {
    let view = rows.view();
    let mut out = vec![[0.0f32; 3]; view.len()];
    view.copy_rows(0, out.iter_mut());
    out
}

#[pymethods]
impl PyStillnessLearner {
    /// A learner with no offset learned; every setting in physical units (see drift-core's
    /// `StillnessSettings`), defaults Fusion's.
    #[new]
    #[pyo3(signature = (*, sample_rate_hz = 1000.0, accel_rate_hz = 100.0,
        rate_threshold_dps = 3.0, rate_sd_threshold_dps = 0.1, accel_sd_threshold_g = 0.01,
        variance_time_constant_s = 0.5, still_for_s = 5.0, time_constant_s = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        sample_rate_hz: f32,
        accel_rate_hz: f32,
        rate_threshold_dps: f32,
        rate_sd_threshold_dps: f32,
        accel_sd_threshold_g: f32,
        variance_time_constant_s: f32,
        still_for_s: f32,
        time_constant_s: Option<f32>,
    ) -> Result<Self, Error> {
        let settings = StillnessSettings {
            sample_rate_hz,
            accel_rate_hz,
            rate_threshold_dps,
            rate_sd_threshold_dps,
            accel_sd_threshold_g,
            variance_time_constant_s,
            still_for_s,
            time_constant_s: time_constant_s
                .unwrap_or(StillnessSettings::default().time_constant_s),
        };
        let learner = StillnessLearner::new(&settings)
            .map_err(|e| Error::Input(format!("invalid stillness setting: {e}")))?;
        Ok(Self { learner, settings })
    }

    /// The offset learned so far, °/s, X, Y, Z.
    #[getter]
    fn offset_dps(&self) -> (f32, f32, f32) {
        let [x, y, z] = self.learner.offset_dps();
        (x, y, z)
    }

    /// The time constant of the offset's low-pass, s.
    #[getter]
    fn time_constant_s(&self) -> f32 {
        self.settings.time_constant_s
    }

    /// Starts from a kept offset, °/s, with the detector cleared.
    fn set_offset(&mut self, offset_dps: &Bound<'_, PyAny>) -> Result<(), Error> {
        let offset_dps = per_axis("offset_dps", offset_dps)?;
        self.learner
            .set_offset(offset_dps)
            .map_err(|e| Error::Input(format!("invalid offset: {e}")))
    }

    /// Clears the still detector and keeps the offset (at switch-on).
    fn reset_detector(&mut self) {
        self.learner.reset_detector();
    }

    /// One accelerometer reading, g.
    fn accelerometer(&mut self, accel_g: &Bound<'_, PyAny>) -> Result<(), Error> {
        self.learner.accelerometer(per_axis("accel_g", accel_g)?);
        Ok(())
    }

    /// One rate sample, °/s: `(rate less the offset, still, learning)`.
    fn update(&mut self, rate_dps: &Bound<'_, PyAny>) -> Result<Learned1, Error> {
        let out = self.learner.update(per_axis("rate_dps", rate_dps)?);
        let [x, y, z] = out.rate_dps;
        Ok(((x, y, z), out.still, out.learning))
    }

    /// n rate samples `(n, 3)`, °/s, in order; with `accel_g` `(m, 3)`, accelerometer row k is
    /// read before rate sample `k · accel_every` (every row whose sample falls in the batch).
    /// Returns the rates less the offset `(n, 3)` float32, and per sample still and learning.
    #[pyo3(signature = (rate_dps, accel_g = None, *, accel_every = 10))]
    fn update_batch<'py>(
        &mut self,
        py: Python<'py>,
        rate_dps: &Bound<'py, PyAny>,
        accel_g: Option<&Bound<'py, PyAny>>,
        accel_every: usize,
    ) -> Result<Learned<'py>, Error> {
        if accel_every == 0 {
            return Err(Error::Input("`accel_every` must be ≥ 1, got 0".into()));
        }
        let rates = rows(&Rows::borrow("rate_dps", rate_dps)?);
        let accel = match accel_g {
            Some(a) if !a.is_none() => rows(&Rows::borrow("accel_g", a)?),
            _ => Vec::new(),
        };
        let n = rates.len();
        let (mut out, mut still, mut learning) = (
            Vec::with_capacity(n * 3),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        let learner = &mut self.learner;
        py.detach(|| {
            for (i, rate) in rates.iter().enumerate() {
                if i % accel_every == 0 {
                    if let Some(a) = accel.get(i / accel_every) {
                        learner.accelerometer(*a);
                    }
                }
                let o = learner.update(*rate);
                out.extend(o.rate_dps);
                still.push(o.still);
                learning.push(o.learning);
            }
        });
        let out = Array2::from_shape_vec((n, 3), out)
            .map_err(|e| Error::Input(format!("internal: output shape ({n}, 3): {e}")))?;
        Ok((
            out.into_pyarray(py),
            still.into_pyarray(py),
            learning.into_pyarray(py),
        ))
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        let [x, y, z] = self.learner.offset_dps();
        format!("StillnessLearner(offset_dps=({x}, {y}, {z}))")
    }
}

/// The whole learner (coefficients, offset, detector) and the settings it was made from, so a
/// restored learner continues where the pickled one stood.
impl crate::pickle_state::Pickled for PyStillnessLearner {
    const KIND: &'static str = "StillnessLearner";

    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        crate::pickle_state::encode(Self::KIND, &(self.settings, self.learner))
    }

    fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        let (settings, learner): (StillnessSettings, StillnessLearner) =
            crate::pickle_state::decode(Self::KIND, state)?;
        // The settings are checked as the constructor checks them: a state edited by hand is
        // refused by name, not run.
        StillnessLearner::new(&settings)
            .map_err(|e| Error::Input(format!("cannot unpickle StillnessLearner: {e}")))?;
        Ok(Self { learner, settings })
    }
}
