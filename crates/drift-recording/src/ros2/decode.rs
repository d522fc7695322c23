//! The CDR of the two standard messages read: `sensor_msgs/msg/Imu` and
//! `sensor_msgs/msg/Temperature` (header, then `float64` fields and fixed arrays).

use crate::cdr::{DecodeError, Decoder};

/// `header.stamp` in ns (and the frame id, which is not kept).
fn header(d: &mut Decoder<'_>) -> Result<i64, DecodeError> {
    let sec = d.i32()?;
    let nanosec = d.u32()?;
    if nanosec >= 1_000_000_000 {
        return Err(format!("header.stamp.nanosec {nanosec} is not below 10⁹"));
    }
    d.string()?;
    Ok(i64::from(sec) * 1_000_000_000 + i64::from(nanosec))
}

/// Decodes a `sensor_msgs/msg/Imu`: its `header.stamp` (ns) and `angular_velocity` (rad/s).
pub fn decode_imu(data: &[u8]) -> Result<(i64, [f64; 3]), DecodeError> {
    let mut d = Decoder::new_ros2(data)?;
    let stamp = header(&mut d)?;
    for _ in 0..(4 + 9) {
        d.f64()?;
    }
    let w = [d.f64()?, d.f64()?, d.f64()?];
    for _ in 0..(9 + 3 + 9) {
        d.f64()?;
    }
    Ok((stamp, w))
}

/// Decodes a `sensor_msgs/msg/Temperature`: its `header.stamp` (ns) and `temperature` (°C).
pub fn decode_temperature(data: &[u8]) -> Result<(i64, f64), DecodeError> {
    let mut d = Decoder::new_ros2(data)?;
    let stamp = header(&mut d)?;
    let celsius = d.f64()?;
    d.f64()?;
    Ok((stamp, celsius))
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
            (12_000_000_500, 21.5)
        );
        assert!(decode_temperature(&e.bytes()[..20]).is_err());
        let mut be = e.bytes().to_vec();
        be[1] = 0;
        assert!(decode_temperature(&be).unwrap_err().contains("big-endian"));
    }
}
