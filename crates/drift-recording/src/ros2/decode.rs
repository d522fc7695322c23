//! The CDR of the two standard messages read: `sensor_msgs/msg/Imu` and
//! `sensor_msgs/msg/Temperature` (header, then `float64` fields and fixed arrays).

use crate::cdr::{DecodeError, Decoder};

/// `header.stamp` in ns and `header.frame_id`.
fn header(d: &mut Decoder<'_>) -> Result<(i64, String), DecodeError> {
    let sec = d.i32()?;
    let nanosec = d.u32()?;
    if nanosec >= 1_000_000_000 {
        return Err(format!("header.stamp.nanosec {nanosec} is not below 10⁹"));
    }
    let frame = d.string()?;
    Ok((i64::from(sec) * 1_000_000_000 + i64::from(nanosec), frame))
}

/// What is read of a `sensor_msgs/msg/Imu`.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuMessage {
    /// `header.stamp`, ns.
    pub stamp_ns: i64,
    /// `header.frame_id`: which sensor.
    pub frame_id: String,
    /// `angular_velocity`, rad/s.
    pub rate: [f64; 3],
    /// `angular_velocity_covariance[0]`: −1 says the rates are not provided (REP-145).
    pub rate_covariance_0: f64,
}

/// Decodes a `sensor_msgs/msg/Imu`.
pub fn decode_imu(data: &[u8]) -> Result<ImuMessage, DecodeError> {
    let mut d = Decoder::new_ros2(data)?;
    let (stamp_ns, frame_id) = header(&mut d)?;
    for _ in 0..(4 + 9) {
        d.f64()?;
    }
    let rate = [d.f64()?, d.f64()?, d.f64()?];
    let rate_covariance_0 = d.f64()?;
    for _ in 0..(8 + 3 + 9) {
        d.f64()?;
    }
    Ok(ImuMessage {
        stamp_ns,
        frame_id,
        rate,
        rate_covariance_0,
    })
}

/// Decodes a `sensor_msgs/msg/Temperature`: its `header.stamp` (ns), `header.frame_id` and
/// `temperature` (°C).
pub fn decode_temperature(data: &[u8]) -> Result<(i64, String, f64), DecodeError> {
    let mut d = Decoder::new_ros2(data)?;
    let (stamp, frame) = header(&mut d)?;
    let celsius = d.f64()?;
    d.f64()?;
    Ok((stamp, frame, celsius))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn imu_and_temperature_messages_decode() {
        let mut e = crate::cdr::Encoder::default();
        e.begin().i32(12).u32(500).string("imu").f64(21.5).f64(0.0);
        assert_eq!(
            decode_temperature(e.bytes()).unwrap(),
            (12_000_000_500, "imu".to_owned(), 21.5)
        );
        assert!(decode_temperature(&e.bytes()[..20]).is_err());
        let mut be = e.bytes().to_vec();
        be[1] = 0;
        assert!(decode_temperature(&be).unwrap_err().contains("big-endian"));
    }
}
