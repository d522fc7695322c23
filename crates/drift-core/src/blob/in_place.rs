//! Decoding the paper's tables in place: the image's payload written field by field into the
//! caller's tables (a `static` in firmware), so the stack holds at most one small leaf value (a
//! curve, the settings, the extension) instead of the whole table by value through serde's nested
//! decoders (docs/embedded.md: from ~40 KB of stack to under 1 KB).
//!
//! The shapes here mirror the derived `Deserialize` impls of the table types, field by field and
//! in order, for formats that encode structs as sequences (postcard, the image's codec). The
//! `blob` tests and the `blob` fuzz target check that both decoders agree on every image.

use heapless::Vec;
use serde::de::{self, DeserializeSeed, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;

use super::legacy::Spliced;
use crate::recommended::{RecommendedAxis, RecommendedTables};
use crate::table::{AmbientCurves, AxisTable, ModifiedTables};
use crate::AXES;

/// A value that can be deserialized by overwriting an existing one.
trait Fill {
    fn fill<'de, D: Deserializer<'de>>(&mut self, deserializer: D) -> Result<(), D::Error>;
}

/// A seed that fills the place it borrows.
struct Place<'a, T>(&'a mut T);

impl<'de, T: Fill> DeserializeSeed<'de> for Place<'_, T> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<(), D::Error> {
        self.0.fill(deserializer)
    }
}

/// Leaves decoded by value: each is small (at most a curve of `R` points or the extension).
macro_rules! by_value {
    ($($ty:ty),* $(,)?) => {$(
        impl Fill for $ty {
            fn fill<'de, D: Deserializer<'de>>(&mut self, deserializer: D) -> Result<(), D::Error> {
                *self = <$ty>::deserialize(deserializer)?;
                Ok(())
            }
        }
    )*};
}

by_value!(
    u32,
    f32,
    crate::settings::Settings,
    crate::extension::Extension,
    crate::warm_start::WarmStart,
    crate::recommended::TurnOn,
);

impl<const R: usize> Fill for crate::table::Curve<R> {
    fn fill<'de, D: Deserializer<'de>>(&mut self, deserializer: D) -> Result<(), D::Error> {
        *self = Self::deserialize(deserializer)?;
        Ok(())
    }
}

/// The next field of a struct read as a sequence; a missing one is an error, as in the derived
/// impls.
fn field<'de, A: SeqAccess<'de>, T: Fill>(
    seq: &mut A,
    place: &mut T,
    index: usize,
    expecting: &'static str,
) -> Result<(), A::Error> {
    match seq.next_element_seed(Place(place))? {
        Some(()) => Ok(()),
        None => Err(de::Error::invalid_length(index, &expecting)),
    }
}

/// A struct's fields filled in order; `$expecting` as the derived impl words it.
macro_rules! fill_struct {
    ($ty:ident < $($param:ident),* > , $name:literal, $expecting:literal, [$($field:ident),+]) => {
        impl<$(const $param: usize),*> Fill for $ty<$($param),*> {
            fn fill<'de, D: Deserializer<'de>>(&mut self, deserializer: D) -> Result<(), D::Error> {
                struct Fields<'a, $(const $param: usize),*>(&'a mut $ty<$($param),*>);
                impl<'de, $(const $param: usize),*> Visitor<'de> for Fields<'_, $($param),*> {
                    type Value = ();
                    fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                        f.write_str($expecting)
                    }
                    #[allow(unused_assignments)]
                    fn visit_seq<S: SeqAccess<'de>>(self, mut seq: S) -> Result<(), S::Error> {
                        let mut index = 0_usize;
                        $(
                            field(&mut seq, &mut self.0.$field, index, $expecting)?;
                            index = index.saturating_add(1);
                        )+
                        Ok(())
                    }
                }
                const FIELDS: &[&str] = &[$(stringify!($field)),+];
                deserializer.deserialize_struct($name, FIELDS, Fields(self))
            }
        }
    };
}

fill_struct!(
    ModifiedTables<R, A, C>,
    "ModifiedTables",
    "struct ModifiedTables",
    [settings, axes, extension]
);
fill_struct!(
    AxisTable<R, A, C>,
    "AxisTable",
    "struct AxisTable",
    [reference_ms, ambients]
);
fill_struct!(
    AmbientCurves<R, C>,
    "AmbientCurves",
    "struct AmbientCurves",
    [
        ambient_celsius,
        initial_bias_dps,
        curves,
        residual_heat_celsius,
        warm_starts
    ]
);

fill_struct!(
    RecommendedTables<R, A, C>,
    "RecommendedTables",
    "struct RecommendedTables",
    [settings, axes]
);
fill_struct!(
    RecommendedAxis<R, A, C>,
    "RecommendedAxis",
    "struct RecommendedAxis",
    [table, turn_on]
);

/// The axes, a fixed-size array: a tuple of `AXES` elements, as serde encodes arrays.
impl<T: Fill> Fill for [T; AXES] {
    fn fill<'de, D: Deserializer<'de>>(&mut self, deserializer: D) -> Result<(), D::Error> {
        struct Elements<'a, T>(&'a mut [T; AXES]);
        impl<'de, T: Fill> Visitor<'de> for Elements<'_, T> {
            type Value = ();
            fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str("an array of length 3")
            }
            fn visit_seq<S: SeqAccess<'de>>(self, mut seq: S) -> Result<(), S::Error> {
                for (index, place) in self.0.iter_mut().enumerate() {
                    field(&mut seq, place, index, "an array of length 3")?;
                }
                Ok(())
            }
        }
        deserializer.deserialize_tuple(AXES, Elements(self))
    }
}

/// A vector filled element by element in place: a default element is pushed and then filled, so
/// an element is never built on the stack and moved. More elements than the capacity: an error,
/// as heapless's own impl gives (never a truncation).
impl<T: Fill + Default, const N: usize> Fill for Vec<T, N> {
    fn fill<'de, D: Deserializer<'de>>(&mut self, deserializer: D) -> Result<(), D::Error> {
        struct Slot<'a, T, const N: usize>(&'a mut Vec<T, N>);
        impl<'de, T: Fill + Default, const N: usize> DeserializeSeed<'de> for Slot<'_, T, N> {
            type Value = ();
            fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<(), D::Error> {
                if self.0.push(T::default()).is_err() {
                    return Err(de::Error::invalid_length(
                        N.saturating_add(1),
                        &"a sequence within the capacity",
                    ));
                }
                match self.0.last_mut() {
                    Some(last) => last.fill(deserializer),
                    None => Err(de::Error::custom("element lost")),
                }
            }
        }
        struct Elements<'a, T, const N: usize>(&'a mut Vec<T, N>);
        impl<'de, T: Fill + Default, const N: usize> Visitor<'de> for Elements<'_, T, N> {
            type Value = ();
            fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str("a sequence")
            }
            fn visit_seq<S: SeqAccess<'de>>(self, mut seq: S) -> Result<(), S::Error> {
                while seq.next_element_seed(Slot(&mut *self.0))?.is_some() {}
                Ok(())
            }
        }
        self.clear();
        deserializer.deserialize_seq(Elements(self))
    }
}

/// Fills `place` from `payload`, which must hold exactly one model. On error `place` is partly
/// written; the caller empties it.
pub(super) fn fill_modified<const R: usize, const A: usize, const C: usize>(
    place: &mut ModifiedTables<R, A, C>,
    payload: Spliced<'_>,
) -> Result<(), postcard::Error> {
    fill_exact(place, payload)
}

/// Fills `place` from `payload`, which must hold exactly one value of its type. On error `place`
/// is partly written; the caller empties it.
#[allow(private_bounds)]
pub(super) fn fill_exact<T: Fill>(
    place: &mut T,
    payload: Spliced<'_>,
) -> Result<(), postcard::Error> {
    let mut deserializer = postcard::Deserializer::from_flavor(payload);
    place.fill(&mut deserializer)?;
    if deserializer.finalize()?.is_empty() {
        Ok(())
    } else {
        Err(postcard::Error::DeserializeBadEncoding)
    }
}

/// Empties `place` in place: no axis keeps a reference time, so validation rejects it.
pub(super) fn empty<const R: usize, const A: usize, const C: usize>(
    place: &mut ModifiedTables<R, A, C>,
) {
    for axis in &mut place.axes {
        empty_axis(axis);
    }
}

/// Empties one axis's table in place (no reference time: validation rejects it).
pub(super) fn empty_axis<const R: usize, const A: usize, const C: usize>(
    axis: &mut AxisTable<R, A, C>,
) {
    axis.reference_ms.clear();
    axis.ambients.clear();
}
