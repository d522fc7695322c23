//! Payloads of format versions 1 and 2: version 3's without the settings' `sample_rate_hz`, the
//! settings' last field, which every model serialises first. They are read through a postcard
//! flavor that supplies that field (0.0: not stated) where version 3 has it, so every model's
//! decoder, by value or in place, reads every version with one set of types.

use postcard::de_flavors::Flavor;

use super::layout::VERSION_3;

/// `sample_rate_hz` as a version-1 or -2 payload implies it: 0.0 (not stated), postcard's `f32`.
const NOT_STATED: [u8; 4] = 0.0_f32.to_le_bytes();

/// The fields of the settings before `sample_rate_hz`, as versions 1 and 2 wrote them.
type SettingsV2 = (f32, f32, f32, f32, u16);

/// A payload read as up to three parts in turn: the bytes before the inserted field, the field,
/// the bytes after it. A read never spans two parts: the insertion sits between two fields.
pub(super) struct Spliced<'de> {
    parts: [&'de [u8]; 3],
}

/// The bytes of a version-`version` payload as version 3 lays them out.
pub(super) fn payload(version: u16, payload: &[u8]) -> Result<Spliced<'_>, postcard::Error> {
    if version >= VERSION_3 {
        return Ok(Spliced {
            parts: [payload, &[], &[]],
        });
    }
    let (_, after) = postcard::take_from_bytes::<SettingsV2>(payload)?;
    let before = payload
        .get(..payload.len().saturating_sub(after.len()))
        .unwrap_or_default();
    Ok(Spliced {
        parts: [before, &NOT_STATED, after],
    })
}

impl<'de> Spliced<'de> {
    /// The part the next byte comes from (empty once all are read).
    fn current(&mut self) -> &mut &'de [u8] {
        let [before, inserted, after] = &mut self.parts;
        if !before.is_empty() {
            before
        } else if !inserted.is_empty() {
            inserted
        } else {
            after
        }
    }
}

impl<'de> Flavor<'de> for Spliced<'de> {
    type Remainder = &'de [u8];
    type Source = &'de [u8];

    fn pop(&mut self) -> postcard::Result<u8> {
        let part = self.current();
        let (&first, rest) = part
            .split_first()
            .ok_or(postcard::Error::DeserializeUnexpectedEnd)?;
        *part = rest;
        Ok(first)
    }

    fn size_hint(&self) -> Option<usize> {
        Some(self.parts.iter().map(|part| part.len()).sum())
    }

    fn try_take_n(&mut self, ct: usize) -> postcard::Result<&'de [u8]> {
        let part = self.current();
        let (taken, rest) = part
            .split_at_checked(ct)
            .ok_or(postcard::Error::DeserializeUnexpectedEnd)?;
        *part = rest;
        Ok(taken)
    }

    fn finalize(self) -> postcard::Result<&'de [u8]> {
        let [before, inserted, after] = self.parts;
        if before.is_empty() && inserted.is_empty() {
            Ok(after)
        } else {
            Ok(before)
        }
    }
}
