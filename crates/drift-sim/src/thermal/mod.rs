//! Thermal physics: an exact solver for linear RC networks and the gyro unit's network.

mod eigen;
pub mod network;
pub mod rc;

#[cfg(test)]
mod tests;
