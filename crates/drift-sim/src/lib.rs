#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod bias;
pub mod campaign;
mod engine;
pub mod error;
pub mod faults;
pub mod hidden;
pub mod motion;
pub mod output_folder;
pub mod overrides;
mod rng;
pub mod schedule;
pub mod simulate;
pub mod size;
pub mod thermal;
pub mod truth;
pub mod unit;
pub mod world;

pub use campaign::{Campaign, Field, Protocol};
pub use error::SimError;
pub use faults::SensorFaults;
pub use hidden::HiddenEffects;
// The recording format lives in drift-recording; re-exported for the simulator's users.
pub use drift_recording::{
    read_campaign_dir, read_recording, AuxChannel, ReadError, Recording, Segment, SegmentLabels,
};
pub use schedule::SeriesKind;
pub use simulate::{
    simulate_campaign, simulate_campaign_until, simulate_campaign_with, Progress, Summary,
    SIMULATING,
};
pub use unit::{UnitModel, UnitParams};
