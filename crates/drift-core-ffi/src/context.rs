//! A unit's context: the decoded tables and the corrector's state, in memory the caller owns.
//! Everything here is safe Rust; `api` is where C's pointers become references to it.

use drift_core::blob::{self, decode_into, Kind};
use drift_core::{
    AxisModel, CorrectorState, Flags, Model, ModifiedAxisState, ModifiedTables, Output, Previous,
    RecommendedTables, Sample, AUX_INPUTS, AXES,
};

use crate::status::GyrodriftStatus;
use crate::types::{GYRODRIFT_CONTEXT_BYTES, GYRODRIFT_LARGE_CONTEXT_BYTES};

/// Written last by a successful `init`, so a context C has only zeroed (or whose `init` failed)
/// is told apart from a ready one by its first word, read as plain bytes.
pub(crate) const READY: u32 = u32::from_le_bytes(*b"GDRC");

/// The models a context runs: the two kinds of table image firmware ships.
pub(crate) enum Tables<const R: usize, const A: usize, const C: usize> {
    Modified(ModifiedTables<R, A, C>),
    Recommended(RecommendedTables<R, A, C>),
}

/// A unit's tables and state. `repr(C)`: `ready` is at offset 0, where `api` reads it.
#[repr(C)]
pub(crate) struct Context<const R: usize, const A: usize, const C: usize> {
    pub(crate) ready: u32,
    state: CorrectorState<ModifiedAxisState>,
    tables: Tables<R, A, C>,
}

/// The default profile's capacities: reference times, ambients, curves per ambient.
pub(crate) const DEFAULT_R: usize = 8;
pub(crate) const DEFAULT_A: usize = 3;
pub(crate) const DEFAULT_C: usize = 16;
/// The large profile's.
pub(crate) const LARGE_R: usize = 16;
pub(crate) const LARGE_A: usize = 6;
pub(crate) const LARGE_C: usize = 32;

/// The default profile's context.
pub(crate) type Default = Context<DEFAULT_R, DEFAULT_A, DEFAULT_C>;
/// The large profile's context.
pub(crate) type Large = Context<LARGE_R, LARGE_A, LARGE_C>;

/// Storage for a default-profile context, for C to allocate (e.g. a `static`, zeroed):
/// `GYRODRIFT_CONTEXT_BYTES`, 8-byte aligned.
#[repr(C, align(8))]
pub struct GyrodriftContext {
    /// Opaque to C.
    pub opaque: [u8; GYRODRIFT_CONTEXT_BYTES],
}

/// Storage for a large-profile context: `GYRODRIFT_LARGE_CONTEXT_BYTES`, 8-byte aligned.
#[repr(C, align(8))]
pub struct GyrodriftLargeContext {
    /// Opaque to C.
    pub opaque: [u8; GYRODRIFT_LARGE_CONTEXT_BYTES],
}

// The storage C allocates holds the context: checked when this crate compiles.
const _: () = {
    assert!(core::mem::size_of::<Default>() <= core::mem::size_of::<GyrodriftContext>());
    assert!(core::mem::align_of::<Default>() <= core::mem::align_of::<GyrodriftContext>());
    assert!(core::mem::size_of::<Large>() <= core::mem::size_of::<GyrodriftLargeContext>());
    assert!(core::mem::align_of::<Large>() <= core::mem::align_of::<GyrodriftLargeContext>());
};

impl<const R: usize, const A: usize, const C: usize> Context<R, A, C> {
    /// Not ready, empty tables (all-zero bytes but the state's flags).
    pub(crate) const EMPTY: Self = Self {
        ready: 0,
        state: CorrectorState::new(),
        tables: Tables::Modified(ModifiedTables::EMPTY),
    };

    /// Decodes `image` in place into the tables of the kind its header names; ready only if it
    /// decodes and validates.
    pub(crate) fn init(&mut self, image: &[u8]) -> GyrodriftStatus {
        self.ready = 0;
        self.state = CorrectorState::new();
        let kind = match blob::header(image) {
            Ok(header) => header.kind,
            Err(error) => return error.into(),
        };
        let decoded = if kind == Kind::Modified as u8 {
            self.tables = Tables::Modified(ModifiedTables::EMPTY);
            match &mut self.tables {
                Tables::Modified(tables) => decode_into(image, tables),
                Tables::Recommended(_) => return GyrodriftStatus::Malformed,
            }
        } else if kind == Kind::Recommended as u8 {
            self.tables = Tables::Recommended(RecommendedTables::EMPTY);
            match &mut self.tables {
                Tables::Recommended(tables) => decode_into(image, tables),
                Tables::Modified(_) => return GyrodriftStatus::Malformed,
            }
        } else {
            return GyrodriftStatus::WrongKind;
        };
        match decoded {
            Ok(()) => {
                self.ready = READY;
                GyrodriftStatus::Ok
            }
            Err(error) => error.into(),
        }
    }

    /// Starts an activation, after `previous` and at a measured `ambient_celsius` where given.
    pub(crate) fn power_on(
        &mut self,
        switch_on_raw: [f32; AXES],
        previous: Option<&mut [Previous; AXES]>,
        ambient_celsius: Option<f32>,
    ) -> Result<[Flags; AXES], GyrodriftStatus> {
        let state = &mut self.state;
        let started = match &self.tables {
            Tables::Modified(tables) => {
                start(state, tables, switch_on_raw, previous, ambient_celsius)
            }
            Tables::Recommended(tables) => {
                start(state, tables, switch_on_raw, previous, ambient_celsius)
            }
        };
        started.map_err(|error| {
            if error.field == "ambient_celsius" {
                GyrodriftStatus::BadAmbient
            } else {
                GyrodriftStatus::BadSwitchOn
            }
        })
    }

    pub(crate) fn correct(&mut self, sample: &Sample, aux: Option<&[f32; AUX_INPUTS]>) -> Output {
        match (&self.tables, aux) {
            (Tables::Modified(tables), None) => self.state.correct(tables, sample),
            (Tables::Recommended(tables), None) => self.state.correct(tables, sample),
            (Tables::Modified(tables), Some(aux)) => {
                self.state.correct_with_aux(tables, sample, aux)
            }
            (Tables::Recommended(tables), Some(aux)) => {
                self.state.correct_with_aux(tables, sample, aux)
            }
        }
    }

    pub(crate) fn keep(&self, previous: &mut [Previous; AXES]) {
        match &self.tables {
            Tables::Modified(tables) => self.state.keep(tables, previous),
            Tables::Recommended(tables) => self.state.keep(tables, previous),
        }
    }

    pub(crate) fn power_off(&mut self) {
        self.state.power_off();
    }
}

/// One of the corrector's four switch-ons, by what is given.
fn start<M>(
    state: &mut CorrectorState<ModifiedAxisState>,
    tables: &M,
    switch_on_raw: [f32; AXES],
    previous: Option<&mut [Previous; AXES]>,
    ambient_celsius: Option<f32>,
) -> Result<[Flags; AXES], drift_core::Error>
where
    M: Model,
    M::Axis: AxisModel<State = ModifiedAxisState>,
{
    match (previous, ambient_celsius) {
        (None, None) => state.power_on(tables, switch_on_raw),
        (Some(kept), None) => state.power_on_after(tables, switch_on_raw, kept),
        (None, Some(ambient)) => state.power_on_at_ambient(tables, switch_on_raw, ambient),
        (Some(kept), Some(ambient)) => {
            state.power_on_after_at_ambient(tables, switch_on_raw, ambient, kept)
        }
    }
}
