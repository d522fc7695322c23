//! What every function returns: 0 on success, a negative code naming what was wrong.

use drift_core::blob::BlobError;

/// The outcome of a call. Negative values are errors; each names one check, in the order
/// `gyrodrift_init` makes them.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyrodriftStatus {
    /// Success.
    Ok = 0,
    /// A pointer argument is null.
    NullPointer = -1,
    /// The context was not initialised by a successful `gyrodrift_init`.
    NotInitialised = -2,
    /// The image's first bytes are `0xFF`: erased flash, no image there.
    Erased = -3,
    /// Not a gyrodrift image (wrong magic) or a header field out of its layout.
    BadHeader = -4,
    /// An image format version this library does not read.
    UnsupportedVersion = -5,
    /// A model this interface does not run (the polynomial baselines): only the paper's tables
    /// and the recommended model.
    WrongKind = -6,
    /// The model needs more reference times, ambients or curves than the context's profile
    /// holds: use the large profile.
    Capacity = -7,
    /// The bytes end before the image does, or go on past it.
    BadLength = -8,
    /// The CRC does not match: a damaged image.
    CrcMismatch = -9,
    /// The payload is not a valid model.
    Malformed = -10,
    /// The model decodes but fails validation.
    Invalid = -11,
    /// `gyrodrift_power_on`: a switch-on temperature is not finite (the state is unchanged).
    BadSwitchOn = -12,
    /// `gyrodrift_power_on_at_ambient`: the measured ambient is not finite (the state is
    /// unchanged).
    BadAmbient = -13,
}

impl From<BlobError> for GyrodriftStatus {
    fn from(error: BlobError) -> Self {
        match error {
            BlobError::Erased => Self::Erased,
            BlobError::BadMagic { .. } | BlobError::BadHeader { .. } => Self::BadHeader,
            BlobError::UnsupportedVersion { .. } => Self::UnsupportedVersion,
            BlobError::WrongKind { .. } => Self::WrongKind,
            BlobError::Capacity { .. } => Self::Capacity,
            BlobError::Truncated { .. } | BlobError::TrailingBytes { .. } => Self::BadLength,
            BlobError::CrcMismatch { .. } => Self::CrcMismatch,
            BlobError::Invalid(_) => Self::Invalid,
            BlobError::Malformed(_) | BlobError::TooLong { .. } | BlobError::BufferTooSmall => {
                Self::Malformed
            }
        }
    }
}
