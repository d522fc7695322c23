//! The `extern "C"` functions: where C's pointers become references. Each profile has the same
//! functions (`gyrodrift_*` for the default context, `gyrodrift_large_*` for the large one), thin
//! wrappers over one generic body each.
//!
//! The conditions every function places on its pointers, beyond "null is an error":
//!
//! - a context pointer points to its profile's storage (`GyrodriftContext` or
//!   `GyrodriftLargeContext`), zeroed or last written by these functions, and no other call uses
//!   the same context at the same time (e.g. an interrupt handler and the main loop);
//! - an array pointer points to as many readable (`const`) or writable values as its
//!   documentation says, which do not overlap the context.

use drift_core::{Previous, Sample, AUX_INPUTS, AXES};

use crate::context::{Context, DEFAULT_A, DEFAULT_C, DEFAULT_R, LARGE_A, LARGE_C, LARGE_R, READY};
use crate::status::GyrodriftStatus;
use crate::types::{GyrodriftOutput, GyrodriftPrevious, GyrodriftSample};
use crate::{GyrodriftContext, GyrodriftLargeContext};

/// The ready context behind `ctx`, or why there is none.
///
/// # Safety
///
/// `ctx` is null or meets the pointer conditions (gyrodrift.h's preamble) for a context of this
/// profile.
unsafe fn ready<'a, const R: usize, const A: usize, const C: usize>(
    ctx: *mut Context<R, A, C>,
) -> Result<&'a mut Context<R, A, C>, GyrodriftStatus> {
    if ctx.is_null() {
        return Err(GyrodriftStatus::NullPointer);
    }
    // SAFETY: `ctx` is non-null, aligned and readable for a whole context (the caller's
    // conditions; the storage's size and alignment are checked in `context`); `ready` is its
    // first field (`repr(C)`), and any four bytes are a valid `u32`.
    let flag = unsafe { ctx.cast::<u32>().read() };
    if flag != READY {
        return Err(GyrodriftStatus::NotInitialised);
    }
    // SAFETY: only `init` writes `READY`, after writing a whole valid context there, and
    // nothing else is using the context during this call (the caller's conditions).
    Ok(unsafe { &mut *ctx })
}

/// `N` values read from `values`.
///
/// # Safety
///
/// `values` is null or points to `N` readable values.
unsafe fn read<T: Copy, const N: usize>(values: *const T) -> Result<[T; N], GyrodriftStatus> {
    if values.is_null() {
        return Err(GyrodriftStatus::NullPointer);
    }
    // SAFETY: non-null and pointing to `N` readable, aligned `T` (the caller's condition); an
    // array of `T` has `T`'s alignment.
    Ok(unsafe { values.cast::<[T; N]>().read() })
}

/// The `N` values at `values`, to read and write.
///
/// # Safety
///
/// `values` is null or points to `N` initialised, writable values used by nothing else during
/// the call.
unsafe fn place<'a, T, const N: usize>(values: *mut T) -> Result<&'a mut [T; N], GyrodriftStatus> {
    if values.is_null() {
        return Err(GyrodriftStatus::NullPointer);
    }
    // SAFETY: non-null, aligned, `N` initialised values, not aliased during the call (the
    // caller's condition).
    Ok(unsafe { &mut *values.cast::<[T; N]>() })
}

fn status(result: Result<(), GyrodriftStatus>) -> GyrodriftStatus {
    result.err().unwrap_or(GyrodriftStatus::Ok)
}

/// # Safety
///
/// As [`gyrodrift_init`].
unsafe fn init<const R: usize, const A: usize, const C: usize>(
    ctx: *mut Context<R, A, C>,
    image: *const u8,
    len: usize,
) -> GyrodriftStatus {
    if ctx.is_null() || image.is_null() {
        return GyrodriftStatus::NullPointer;
    }
    // SAFETY: `image` points to `len` readable bytes that nothing writes during the call (the
    // caller's condition).
    let image = unsafe { core::slice::from_raw_parts(image, len) };
    // SAFETY: `ctx` is aligned and writable for a whole context (the caller's condition; size
    // and alignment checked in `context`). `write` neither reads nor drops the bytes there,
    // which need not be a valid context yet.
    unsafe { ctx.write(Context::EMPTY) };
    // SAFETY: a valid context was just written there, and nothing else uses it during the call.
    let context = unsafe { &mut *ctx };
    context.init(image)
}

/// # Safety
///
/// As [`gyrodrift_power_on_after`] (`previous` may be null for [`gyrodrift_power_on`]).
unsafe fn power_on<const R: usize, const A: usize, const C: usize>(
    ctx: *mut Context<R, A, C>,
    switch_on_raw: *const f32,
    previous: Option<*mut GyrodriftPrevious>,
    ambient_celsius: Option<f32>,
    flags: *mut u16,
) -> GyrodriftStatus {
    status((|| {
        // SAFETY: the caller's conditions on each pointer.
        let context = unsafe { ready(ctx) }?;
        // SAFETY: as above.
        let raw = unsafe { read::<f32, AXES>(switch_on_raw) }?;
        let kept = match previous {
            // SAFETY: as above.
            Some(previous) => Some(unsafe { place::<GyrodriftPrevious, AXES>(previous) }?),
            None => None,
        };
        let mut theirs = kept.as_deref().map(|kept| kept.map(Previous::from));
        let started = context.power_on(raw, theirs.as_mut(), ambient_celsius);
        if let (Some(kept), Some(theirs)) = (kept, theirs) {
            *kept = theirs.map(GyrodriftPrevious::from);
        }
        let started = started?;
        if !flags.is_null() {
            // SAFETY: non-null, so three writable `u16` (the caller's condition).
            let out = unsafe { place::<u16, AXES>(flags) }?;
            *out = started.map(|flag| flag.0);
        }
        Ok(())
    })())
}

/// # Safety
///
/// As [`gyrodrift_correct_with_aux`] (`aux` may be null for [`gyrodrift_correct`]).
unsafe fn correct<const R: usize, const A: usize, const C: usize>(
    ctx: *mut Context<R, A, C>,
    sample: *const GyrodriftSample,
    aux: *const f32,
    output: *mut GyrodriftOutput,
) -> GyrodriftStatus {
    status((|| {
        // SAFETY: the caller's conditions on each pointer.
        let context = unsafe { ready(ctx) }?;
        // SAFETY: as above.
        let [sample] = unsafe { read::<GyrodriftSample, 1>(sample) }?;
        let aux = if aux.is_null() {
            None
        } else {
            // SAFETY: as above.
            Some(unsafe { read::<f32, AUX_INPUTS>(aux) }?)
        };
        // SAFETY: as above.
        let [out] = unsafe { place::<GyrodriftOutput, 1>(output) }?;
        *out = context.correct(&Sample::from(&sample), aux.as_ref()).into();
        Ok(())
    })())
}

/// # Safety
///
/// As [`gyrodrift_keep`].
unsafe fn keep<const R: usize, const A: usize, const C: usize>(
    ctx: *mut Context<R, A, C>,
    previous: *mut GyrodriftPrevious,
) -> GyrodriftStatus {
    status((|| {
        // SAFETY: the caller's conditions on each pointer.
        let context = unsafe { ready(ctx) }?;
        // SAFETY: as above.
        let kept = unsafe { place::<GyrodriftPrevious, AXES>(previous) }?;
        let mut theirs = kept.map(Previous::from);
        context.keep(&mut theirs);
        *kept = theirs.map(GyrodriftPrevious::from);
        Ok(())
    })())
}

/// # Safety
///
/// As [`gyrodrift_power_off`].
unsafe fn power_off<const R: usize, const A: usize, const C: usize>(
    ctx: *mut Context<R, A, C>,
) -> GyrodriftStatus {
    // SAFETY: the caller's condition on `ctx`.
    status(unsafe { ready(ctx) }.map(Context::power_off))
}

/// A sample from 16-bit temperature counts (`GYRODRIFT_MISSING_TEMPERATURE`: no reading on that
/// axis), as drift-core's `Sample::from_counts`: `rate_dps` and `temperature_counts` point to
/// three values each; the sample is written to `sample`.
///
/// # Safety
///
/// The pointer conditions (gyrodrift.h's preamble) on array pointers.
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_sample_from_counts(
    since_power_on_ms: u32,
    rate_dps: *const f32,
    temperature_counts: *const i16,
    sample: *mut GyrodriftSample,
) -> GyrodriftStatus {
    status((|| {
        // SAFETY: the caller's conditions on each pointer.
        let rate = unsafe { read::<f32, AXES>(rate_dps) }?;
        // SAFETY: as above.
        let counts = unsafe { read::<i16, AXES>(temperature_counts) }?;
        // SAFETY: as above.
        let [out] = unsafe { place::<GyrodriftSample, 1>(sample) }?;
        let made = Sample::from_counts(since_power_on_ms, rate, counts);
        *out = GyrodriftSample {
            since_power_on_ms: made.since_power_on_ms,
            rate_dps: made.rate_dps,
            temperature_raw: made.temperature_raw,
        };
        Ok(())
    })())
}

/// Decodes the table image at `image` (`len` bytes: the image exactly, e.g. from the length its
/// header gives) into `ctx`, which is then ready for a unit, not powered on. The paper's tables
/// and the recommended model are run; the image is read during the call only. On error the
/// context is not ready (every other call returns `GYRODRIFT_STATUS_NOT_INITIALISED`).
///
/// # Safety
///
/// `ctx` and `image` are null or meet the pointer conditions (gyrodrift.h's preamble) (`image`:
/// `len` readable bytes).
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_init(
    ctx: *mut GyrodriftContext,
    image: *const u8,
    len: usize,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe { init::<DEFAULT_R, DEFAULT_A, DEFAULT_C>(ctx.cast(), image, len) }
}

/// Starts an activation from the raw temperatures at switch-on (`switch_on_raw`, three values),
/// with nothing known of the previous one. Writes the activation's flags to `flags` (three
/// values) unless it is null. A non-finite temperature is refused
/// (`GYRODRIFT_STATUS_BAD_SWITCH_ON`), the state unchanged.
///
/// # Safety
///
/// The pointer conditions (gyrodrift.h's preamble) on `ctx`, `switch_on_raw` and `flags` (which
/// may be null).
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_power_on(
    ctx: *mut GyrodriftContext,
    switch_on_raw: *const f32,
    flags: *mut u16,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe {
        power_on::<DEFAULT_R, DEFAULT_A, DEFAULT_C>(ctx.cast(), switch_on_raw, None, None, flags)
    }
}

/// [`gyrodrift_power_on`] with what was kept of the previous activation (`previous`, three
/// values, both fields NaN before the first): tables keyed by heating history read the residual
/// heat from it. Writes this activation's ambient into `previous`; [`gyrodrift_keep`] then
/// records its switch-off temperature.
///
/// # Safety
///
/// The pointer conditions (gyrodrift.h's preamble) on `ctx`, `switch_on_raw`, `previous` and
/// `flags` (which may be null).
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_power_on_after(
    ctx: *mut GyrodriftContext,
    switch_on_raw: *const f32,
    previous: *mut GyrodriftPrevious,
    flags: *mut u16,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe {
        power_on::<DEFAULT_R, DEFAULT_A, DEFAULT_C>(
            ctx.cast(),
            switch_on_raw,
            Some(previous),
            None,
            flags,
        )
    }
}

/// [`gyrodrift_power_on`] with the ambient the instrument measured at switch-on
/// (`ambient_celsius`, °C, one for the unit: an air or board thermistor): the paper's stage 2 and
/// initial bias are read there, not at the switch-on temperature; time since switch-on and the
/// rise as always. An ambient outside the calibration is flagged as a switch-on temperature is; a
/// non-finite one is refused (`GYRODRIFT_STATUS_BAD_AMBIENT`), the state unchanged. The same
/// per-sample cost as after [`gyrodrift_power_on`].
///
/// # Safety
///
/// The pointer conditions (gyrodrift.h's preamble) on `ctx`, `switch_on_raw` and `flags` (which
/// may be null).
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_power_on_at_ambient(
    ctx: *mut GyrodriftContext,
    switch_on_raw: *const f32,
    ambient_celsius: f32,
    flags: *mut u16,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe {
        power_on::<DEFAULT_R, DEFAULT_A, DEFAULT_C>(
            ctx.cast(),
            switch_on_raw,
            None,
            Some(ambient_celsius),
            flags,
        )
    }
}

/// [`gyrodrift_power_on_at_ambient`] with what was kept of the previous activation (`previous`,
/// as for [`gyrodrift_power_on_after`]): the measured ambient replaces the estimate and is written
/// into `previous`.
///
/// # Safety
///
/// The pointer conditions (gyrodrift.h's preamble) on `ctx`, `switch_on_raw`, `previous` and
/// `flags` (which may be null).
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_power_on_after_at_ambient(
    ctx: *mut GyrodriftContext,
    switch_on_raw: *const f32,
    ambient_celsius: f32,
    previous: *mut GyrodriftPrevious,
    flags: *mut u16,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe {
        power_on::<DEFAULT_R, DEFAULT_A, DEFAULT_C>(
            ctx.cast(),
            switch_on_raw,
            Some(previous),
            Some(ambient_celsius),
            flags,
        )
    }
}

/// Corrects one sample into `output`. Never fails on the sample's values: clamps, holds and
/// faults are in `output->flags`; before a power-on the rates pass through, flagged.
///
/// # Safety
///
/// The pointer conditions (gyrodrift.h's preamble) on `ctx`, `sample` and `output`.
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_correct(
    ctx: *mut GyrodriftContext,
    sample: *const GyrodriftSample,
    output: *mut GyrodriftOutput,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe {
        correct::<DEFAULT_R, DEFAULT_A, DEFAULT_C>(ctx.cast(), sample, core::ptr::null(), output)
    }
}

/// [`gyrodrift_correct`] with the auxiliary inputs (`aux`, `GYRODRIFT_AUX_INPUTS` values) the
/// extended model's terms read.
///
/// # Safety
///
/// The pointer conditions (gyrodrift.h's preamble) on `ctx`, `sample`, `aux` and `output`.
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_correct_with_aux(
    ctx: *mut GyrodriftContext,
    sample: *const GyrodriftSample,
    aux: *const f32,
    output: *mut GyrodriftOutput,
) -> GyrodriftStatus {
    if aux.is_null() {
        return GyrodriftStatus::NullPointer;
    }
    // SAFETY: the caller's conditions, passed on.
    unsafe { correct::<DEFAULT_R, DEFAULT_A, DEFAULT_C>(ctx.cast(), sample, aux, output) }
}

/// Records this activation's last good temperature per axis into `previous` (three values, from
/// [`gyrodrift_power_on_after`]) as its switch-off temperature: call it before power-off, or
/// periodically if power can go without warning.
///
/// # Safety
///
/// The pointer conditions (gyrodrift.h's preamble) on `ctx` and `previous`.
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_keep(
    ctx: *mut GyrodriftContext,
    previous: *mut GyrodriftPrevious,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe { keep::<DEFAULT_R, DEFAULT_A, DEFAULT_C>(ctx.cast(), previous) }
}

/// Ends the activation: samples pass through, flagged, until the next power-on.
///
/// # Safety
///
/// The pointer conditions (gyrodrift.h's preamble) on `ctx`.
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_power_off(ctx: *mut GyrodriftContext) -> GyrodriftStatus {
    // SAFETY: the caller's condition, passed on.
    unsafe { power_off::<DEFAULT_R, DEFAULT_A, DEFAULT_C>(ctx.cast()) }
}

/// [`gyrodrift_init`] for the large profile (`gyrodrift_large_context`).
///
/// # Safety
///
/// As [`gyrodrift_init`].
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_large_init(
    ctx: *mut GyrodriftLargeContext,
    image: *const u8,
    len: usize,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe { init::<LARGE_R, LARGE_A, LARGE_C>(ctx.cast(), image, len) }
}

/// [`gyrodrift_power_on`] for the large profile (`gyrodrift_large_context`).
///
/// # Safety
///
/// As [`gyrodrift_power_on`].
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_large_power_on(
    ctx: *mut GyrodriftLargeContext,
    switch_on_raw: *const f32,
    flags: *mut u16,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe { power_on::<LARGE_R, LARGE_A, LARGE_C>(ctx.cast(), switch_on_raw, None, None, flags) }
}

/// [`gyrodrift_power_on_after`] for the large profile (`gyrodrift_large_context`).
///
/// # Safety
///
/// As [`gyrodrift_power_on_after`].
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_large_power_on_after(
    ctx: *mut GyrodriftLargeContext,
    switch_on_raw: *const f32,
    previous: *mut GyrodriftPrevious,
    flags: *mut u16,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe {
        power_on::<LARGE_R, LARGE_A, LARGE_C>(
            ctx.cast(),
            switch_on_raw,
            Some(previous),
            None,
            flags,
        )
    }
}

/// [`gyrodrift_power_on_at_ambient`] for the large profile (`gyrodrift_large_context`).
///
/// # Safety
///
/// As [`gyrodrift_power_on_at_ambient`].
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_large_power_on_at_ambient(
    ctx: *mut GyrodriftLargeContext,
    switch_on_raw: *const f32,
    ambient_celsius: f32,
    flags: *mut u16,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe {
        power_on::<LARGE_R, LARGE_A, LARGE_C>(
            ctx.cast(),
            switch_on_raw,
            None,
            Some(ambient_celsius),
            flags,
        )
    }
}

/// [`gyrodrift_power_on_after_at_ambient`] for the large profile (`gyrodrift_large_context`).
///
/// # Safety
///
/// As [`gyrodrift_power_on_after_at_ambient`].
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_large_power_on_after_at_ambient(
    ctx: *mut GyrodriftLargeContext,
    switch_on_raw: *const f32,
    ambient_celsius: f32,
    previous: *mut GyrodriftPrevious,
    flags: *mut u16,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe {
        power_on::<LARGE_R, LARGE_A, LARGE_C>(
            ctx.cast(),
            switch_on_raw,
            Some(previous),
            Some(ambient_celsius),
            flags,
        )
    }
}

/// [`gyrodrift_correct`] for the large profile (`gyrodrift_large_context`).
///
/// # Safety
///
/// As [`gyrodrift_correct`].
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_large_correct(
    ctx: *mut GyrodriftLargeContext,
    sample: *const GyrodriftSample,
    output: *mut GyrodriftOutput,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe { correct::<LARGE_R, LARGE_A, LARGE_C>(ctx.cast(), sample, core::ptr::null(), output) }
}

/// [`gyrodrift_correct_with_aux`] for the large profile (`gyrodrift_large_context`).
///
/// # Safety
///
/// As [`gyrodrift_correct_with_aux`].
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_large_correct_with_aux(
    ctx: *mut GyrodriftLargeContext,
    sample: *const GyrodriftSample,
    aux: *const f32,
    output: *mut GyrodriftOutput,
) -> GyrodriftStatus {
    if aux.is_null() {
        return GyrodriftStatus::NullPointer;
    }
    // SAFETY: the caller's conditions, passed on.
    unsafe { correct::<LARGE_R, LARGE_A, LARGE_C>(ctx.cast(), sample, aux, output) }
}

/// [`gyrodrift_keep`] for the large profile (`gyrodrift_large_context`).
///
/// # Safety
///
/// As [`gyrodrift_keep`].
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_large_keep(
    ctx: *mut GyrodriftLargeContext,
    previous: *mut GyrodriftPrevious,
) -> GyrodriftStatus {
    // SAFETY: the caller's conditions, passed on.
    unsafe { keep::<LARGE_R, LARGE_A, LARGE_C>(ctx.cast(), previous) }
}

/// [`gyrodrift_power_off`] for the large profile (`gyrodrift_large_context`).
///
/// # Safety
///
/// As [`gyrodrift_power_off`].
#[no_mangle]
pub unsafe extern "C" fn gyrodrift_large_power_off(
    ctx: *mut GyrodriftLargeContext,
) -> GyrodriftStatus {
    // SAFETY: the caller's condition, passed on.
    unsafe { power_off::<LARGE_R, LARGE_A, LARGE_C>(ctx.cast()) }
}
