//! An activation as the means of consecutive blocks of samples: what analyses that only ever look
//! through the 1-s low-pass need, at a fraction of the samples.
//!
//! The mean of ten consecutive 0.1-s block means is the mean of the 1-s of samples they cover, so
//! a 1-s centred moving average of the blocks equals the full-rate one at every block start
//! (exactly, up to rounding); what is lost is what lies within a block — noise and edges shorter
//! than the block, which the 1-s window removes anyway. Temperatures stay raw integers (a block
//! mean rounds to the nearest count: ±0.5 count, a fraction of the sensor's own noise).

use std::collections::BTreeMap;

use crate::segment::{AuxChannel, Segment, TEMPERATURE_MISSING_RAW};

/// `segment` at `rate_hz` (a divisor of its own rate): each output sample is the mean of the
/// input samples whose index since switch-on falls in one block of `sample_rate_hz / rate_hz`
/// samples, stamped at the block's start. A block without samples (a gap in the recording) stays a
/// gap; a block's missing temperature readings are left out of its mean, and a block with none is
/// missing. Auxiliary channels recorded faster than `rate_hz` at a multiple of it are averaged the
/// same way; slower ones are kept as recorded.
///
/// Returns `None` where `rate_hz` does not divide the segment's rate below it (nothing to gain, or
/// no exact block): the caller keeps the segment as it is.
pub fn block_means(segment: &Segment, rate_hz: u32) -> Option<Segment> {
    let block = block_length(segment.sample_rate_hz, rate_hz)?;
    let mut since_power_on = Vec::with_capacity(segment.len() / block as usize + 1);
    let mut rate_dps: [Vec<f32>; 3] = Default::default();
    let mut temperature_raw: [Vec<i16>; 3] = Default::default();
    let mut start = 0;
    while start < segment.len() {
        let index = segment.since_power_on[start] / block;
        let end = start
            + segment.since_power_on[start..]
                .iter()
                .take_while(|&&i| i / block == index)
                .count();
        since_power_on.push(index);
        for axis in 0..3 {
            rate_dps[axis].push(mean_rate(&segment.rate_dps[axis][start..end]));
            temperature_raw[axis]
                .push(mean_temperature(&segment.temperature_raw[axis][start..end]));
        }
        start = end;
    }
    let aux: BTreeMap<String, AuxChannel> = segment
        .aux
        .iter()
        .map(|(name, channel)| (name.clone(), aux_block_means(channel, rate_hz)))
        .collect();
    Some(Segment {
        labels: segment.labels.clone(),
        sample_rate_hz: rate_hz,
        power_on_ns: segment.power_on_ns,
        since_power_on,
        rate_dps,
        temperature_raw,
        temperature_scale: segment.temperature_scale,
        aux,
    })
}

/// Samples per block from `from_hz` to `to_hz`, when that is a whole number above 1.
fn block_length(from_hz: u32, to_hz: u32) -> Option<u32> {
    (to_hz > 0 && from_hz > to_hz && from_hz % to_hz == 0).then(|| from_hz / to_hz)
}

fn mean_rate(values: &[f32]) -> f32 {
    let sum: f64 = values.iter().map(|&v| f64::from(v)).sum();
    (sum / values.len().max(1) as f64) as f32
}

fn mean_temperature(raw: &[i16]) -> i16 {
    let (sum, count) = raw
        .iter()
        .filter(|&&r| r != TEMPERATURE_MISSING_RAW)
        .fold((0i64, 0i64), |(s, c), &r| (s + i64::from(r), c + 1));
    if count == 0 {
        return TEMPERATURE_MISSING_RAW;
    }
    // Rounded half away from zero; a mean of i16 readings is within their range.
    let mean = (sum as f64 / count as f64).round();
    mean.clamp(
        f64::from(TEMPERATURE_MISSING_RAW) + 1.0,
        f64::from(i16::MAX),
    ) as i16
}

fn aux_block_means(channel: &AuxChannel, rate_hz: u32) -> AuxChannel {
    let Some(block) = block_length(channel.sample_rate_hz, rate_hz) else {
        return channel.clone();
    };
    AuxChannel {
        unit: channel.unit.clone(),
        sample_rate_hz: rate_hz,
        values: channel
            .values
            .chunks(block as usize)
            .map(|chunk| {
                // NaN (a missing reading) stays out of the mean, as a missing temperature does.
                let (sum, count) = chunk
                    .iter()
                    .filter(|v| v.is_finite())
                    .fold((0.0f64, 0usize), |(s, c), &v| (s + f64::from(v), c + 1));
                if count == 0 {
                    f32::NAN
                } else {
                    (sum / count as f64) as f32
                }
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segment::{SegmentLabels, SeriesKind, TemperatureScale};

    fn segment(n: u32, rate_hz: u32) -> Segment {
        let since_power_on: Vec<u32> = (0..n).collect();
        let rate: Vec<f32> = since_power_on.iter().map(|&i| i as f32 * 0.01).collect();
        let temperature: Vec<i16> = since_power_on
            .iter()
            .map(|&i| 6000 + (i / 7) as i16)
            .collect();
        let mut aux = BTreeMap::new();
        aux.insert(
            "supply_voltage".to_owned(),
            AuxChannel {
                unit: "V".into(),
                sample_rate_hz: rate_hz,
                values: since_power_on
                    .iter()
                    .map(|&i| 5.0 + i as f32 * 1e-3)
                    .collect(),
            },
        );
        aux.insert(
            "slow".to_owned(),
            AuxChannel {
                unit: "V".into(),
                sample_rate_hz: 1,
                values: vec![1.0, 2.0],
            },
        );
        Segment {
            labels: SegmentLabels {
                unit_id: "U".into(),
                set_point_celsius: 30.0,
                session_set_point_celsius: Some(30.0),
                series_kind: SeriesKind::Protocol,
                series: 1,
                repeat: 1,
                activation: 1,
                interval_min: Some(1.0),
                off_before_s: None,
            },
            sample_rate_hz: rate_hz,
            power_on_ns: 7,
            since_power_on,
            rate_dps: [rate.clone(), rate.clone(), rate],
            temperature_raw: [temperature.clone(), temperature.clone(), temperature],
            temperature_scale: TemperatureScale::default(),
            aux,
        }
    }

    #[test]
    fn blocks_are_the_means_of_their_samples_stamped_at_their_start() {
        let full = segment(1000, 100);
        let coarse = block_means(&full, 10).unwrap();
        assert_eq!(coarse.sample_rate_hz, 10);
        assert_eq!(coarse.len(), 100);
        assert_eq!(coarse.since_power_on[3], 3);
        // Samples 30..40: rates 0.30 … 0.39, mean 0.345.
        assert!((coarse.rate_dps[1][3] - 0.345).abs() < 1e-6);
        let expected: f64 = (30..40).map(|i| f64::from(6000 + i / 7)).sum::<f64>() / 10.0;
        assert_eq!(coarse.temperature_raw[2][3], expected.round() as i16);
        let supply = &coarse.aux["supply_voltage"];
        assert_eq!((supply.sample_rate_hz, supply.values.len()), (10, 100));
        assert!((supply.values[3] - 5.0345).abs() < 1e-5);
        assert_eq!(coarse.aux["slow"], full.aux["slow"]);
        assert_eq!(coarse.labels, full.labels);
        assert_eq!(coarse.power_on_ns, full.power_on_ns);
    }

    #[test]
    fn a_gap_stays_a_gap_and_missing_readings_stay_out_of_the_mean() {
        let mut full = segment(1000, 100);
        // Drop samples 200..=349 (blocks 20–34 gone, none partly) and one reading of block 50.
        full.since_power_on.drain(200..350);
        for axis in 0..3 {
            full.rate_dps[axis].drain(200..350);
            full.temperature_raw[axis].drain(200..350);
        }
        full.temperature_raw[0][500 - 150] = TEMPERATURE_MISSING_RAW;
        let coarse = block_means(&full, 10).unwrap();
        assert_eq!(coarse.len(), 85);
        assert_eq!(coarse.since_power_on[19..21], [19, 35]);
        let expected: f64 = (501..510).map(|i| f64::from(6000 + i / 7)).sum::<f64>() / 9.0;
        let block_50 = coarse.since_power_on.iter().position(|&i| i == 50).unwrap();
        assert_eq!(coarse.temperature_raw[0][block_50], expected.round() as i16);
    }

    #[test]
    fn a_centred_one_second_mean_of_the_blocks_is_the_full_rate_one_at_each_block_start() {
        let full = segment(3000, 1000);
        let coarse = block_means(&full, 10).unwrap();
        let window = |v: &[f32], centre: usize, half: usize| -> f64 {
            v[centre - half..centre + half]
                .iter()
                .map(|&x| f64::from(x))
                .sum::<f64>()
                / (2 * half) as f64
        };
        for block in 5..25 {
            let fine = window(&full.rate_dps[0], block * 100, 500);
            let blocks = window(&coarse.rate_dps[0], block, 5);
            assert!(
                (fine - blocks).abs() < 1e-5,
                "block {block}: {fine} vs {blocks}"
            );
        }
    }

    #[test]
    fn a_rate_that_does_not_divide_is_left_to_the_caller() {
        assert!(block_means(&segment(10, 10), 10).is_none());
        assert!(block_means(&segment(10, 333), 10).is_none());
        assert!(block_means(&segment(10, 100), 0).is_none());
        assert!(block_means(&segment(10, 100), 10).is_some());
    }
}
