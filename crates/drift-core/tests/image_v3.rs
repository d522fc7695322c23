//! Image format version 3: the settings carry the sample rate their stuck timeout was converted
//! at. A committed image, the settings in physical units through it, and every model kind read
//! from its version-2 form.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]
#![allow(clippy::arithmetic_side_effects, clippy::float_cmp, missing_docs)]

mod common;

use common::fixture::{self, FixtureTables};
use drift_core::blob::{
    decode, decode_into, encode_for, header, Provenance, FORMAT_VERSION, HEADER_LEN, VERSION_2,
    VERSION_3,
};
use drift_core::{
    Error, Location, PolynomialAxis, PolynomialTables, Problem, RecommendedTables,
    RelativePolynomialAxis, RelativePolynomialTables, SensorSettings, Settings,
};

/// A sensor at 1000 Hz stuck after 2 s, 256 LSB/°C reading 0 at 25 °C.
const SENSOR: SensorSettings = SensorSettings {
    raw_per_celsius: 256.0,
    raw_at_zero_celsius: -6400.0,
    sample_rate_hz: 1000.0,
    stuck_after_seconds: 2.0,
    ..SensorSettings::DEFAULT
};

fn tables() -> FixtureTables {
    let mut tables = fixture::modified();
    tables.settings = Settings::from_sensor(&SENSOR).unwrap();
    tables
}

fn encoded<M: drift_core::blob::Image>(model: &M, provenance: &Provenance) -> Vec<u8> {
    let mut buffer = vec![0; 64 * 1024];
    let len = encode_for(model, provenance, &mut buffer).unwrap();
    buffer.truncate(len);
    buffer
}

/// A version-2 image of `image`'s model: the same header but its version, the payload without
/// `sample_rate_hz`, resealed.
fn as_v2(image: &[u8]) -> Vec<u8> {
    let payload = &image[HEADER_LEN..image.len() - 4];
    let varint = payload[16..].iter().position(|b| b & 0x80 == 0).unwrap() + 1;
    let at = 16 + varint;
    let mut old: Vec<u8> = image[..HEADER_LEN].to_vec();
    old[4..6].copy_from_slice(&VERSION_2.to_le_bytes());
    let new_len = u32::try_from(payload.len() - 4).unwrap();
    old[8..12].copy_from_slice(&new_len.to_le_bytes());
    old.extend_from_slice(&payload[..at]);
    old.extend_from_slice(&payload[at + 4..]);
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&old);
    old.extend_from_slice(&crc.to_le_bytes());
    old
}

/// The committed version-3 image (`GYRODRIFT_BLESS=1` rewrites it after a deliberate format change,
/// which is a new [`FORMAT_VERSION`]): it loads, in place too, with the sensor's settings, and the
/// encoder still writes these bytes.
#[test]
fn the_committed_v3_image_loads_and_is_written_the_same() {
    const PATH: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../testdata/image-v3-modified.bin"
    );
    let provenance = Provenance::new("unit-07", "0.1.0", 20_261_128).unwrap();
    if std::env::var_os("GYRODRIFT_BLESS").is_some() {
        std::fs::write(PATH, encoded(&tables(), &provenance)).unwrap();
    }
    let committed = std::fs::read(PATH).unwrap();
    assert_eq!(FORMAT_VERSION, VERSION_3);
    assert_eq!(header(&committed).unwrap().version, VERSION_3);
    let decoded: FixtureTables = decode(&committed).unwrap();
    assert_eq!(decoded, tables());
    assert_eq!(decoded.settings.sample_rate_hz, 1000.0);
    assert_eq!(decoded.settings.stuck_after_samples, 2000);
    assert_eq!(decoded.settings.stuck_after_seconds(), Some(2.0));
    assert_eq!(decoded.settings.raw_per_celsius, 256.0);
    let mut in_place: FixtureTables = FixtureTables::EMPTY;
    decode_into(&committed, &mut in_place).unwrap();
    assert_eq!(in_place, decoded);
    assert_eq!(encoded(&tables(), &provenance), committed);
}

/// Every model kind's version-2 payload reads as its version-3 one with the rate not stated, by
/// value and (the paper's tables and the recommended model) in place.
#[test]
fn every_kind_reads_its_version_2_form() {
    let none = Provenance::default();
    let stated = Settings::from_sensor(&SENSOR).unwrap();
    let not_stated = Settings {
        sample_rate_hz: 0.0,
        ..stated
    };

    let v3 = encoded(&tables(), &none);
    let v2 = as_v2(&v3);
    common::legacy::assert_is_v2_with_rate(
        &v2[HEADER_LEN..v2.len() - 4],
        &v3[HEADER_LEN..v3.len() - 4],
        1000.0,
    );
    let mut expected = tables();
    expected.settings = not_stated;
    assert_eq!(decode::<FixtureTables>(&v2).unwrap(), expected);
    let mut in_place = FixtureTables::EMPTY;
    decode_into(&v2, &mut in_place).unwrap();
    assert_eq!(in_place, expected);

    let recommended = RecommendedTables {
        settings: stated,
        ..fixture::recommended()
    };
    let v2 = as_v2(&encoded(&recommended, &none));
    let mut place: common::fixture::FixtureRecommended = RecommendedTables::EMPTY;
    decode_into(&v2, &mut place).unwrap();
    assert_eq!(place.settings, not_stated);
    assert_eq!(place.axes, recommended.axes);

    let axis = PolynomialAxis {
        range_celsius: [20.0, 40.0],
        coefficients: heapless::Vec::from_slice(&[0.5, 0.01, -0.0002]).unwrap(),
    };
    let polynomial =
        PolynomialTables::try_new(stated, [axis.clone(), axis.clone(), axis.clone()]).unwrap();
    let read: PolynomialTables = decode(&as_v2(&encoded(&polynomial, &none))).unwrap();
    assert_eq!(read.settings, not_stated);
    assert_eq!(read.axes, polynomial.axes);

    let pair = RelativePolynomialAxis {
        drift: axis.clone(),
        turn_on: axis,
    };
    let relative = RelativePolynomialTables {
        settings: stated,
        axes: [pair.clone(), pair.clone(), pair],
    };
    let read: RelativePolynomialTables = decode(&as_v2(&encoded(&relative, &none))).unwrap();
    assert_eq!(read.settings, not_stated);
    assert_eq!(read.axes, relative.axes);
}

/// The conversion happens once, rounded; each bad value is named.
#[test]
fn sensor_settings_convert_once_and_name_bad_values() {
    const AT_100_HZ: Result<Settings, Error> = Settings::from_sensor(&SensorSettings {
        sample_rate_hz: 100.0,
        ..SensorSettings::DEFAULT
    });
    assert_eq!(AT_100_HZ.unwrap().stuck_after_samples, 200);
    assert_eq!(
        Settings::from_sensor(&SensorSettings::DEFAULT).unwrap(),
        Settings {
            sample_rate_hz: 1000.0,
            ..Settings::DEFAULT
        }
    );
    let never = Settings::from_sensor(&SensorSettings {
        stuck_after_seconds: 0.0,
        ..SENSOR
    })
    .unwrap();
    assert_eq!(never.stuck_after_samples, 0);
    assert_eq!(Settings::DEFAULT.stuck_after_seconds(), None);

    let named = |sensor: SensorSettings| {
        let Error { field, at, problem } = Settings::from_sensor(&sensor).unwrap_err();
        assert_eq!(at, Location::default());
        (field, problem)
    };
    assert_eq!(
        named(SensorSettings {
            sample_rate_hz: 0.0,
            ..SENSOR
        }),
        ("sample_rate_hz", Problem::NotPositive)
    );
    assert_eq!(
        named(SensorSettings {
            stuck_after_seconds: f32::NAN,
            ..SENSOR
        }),
        ("stuck_after_seconds", Problem::NonFinite)
    );
    assert_eq!(
        named(SensorSettings {
            stuck_after_seconds: -1.0,
            ..SENSOR
        }),
        ("stuck_after_seconds", Problem::Negative)
    );
    assert_eq!(
        named(SensorSettings {
            raw_per_celsius: 0.0,
            ..SENSOR
        }),
        ("raw_per_celsius", Problem::NotPositive)
    );
    // 65.6 s at 1000 Hz is 65 600 samples: more than the counter holds.
    let too_long = named(SensorSettings {
        stuck_after_seconds: 65.6,
        ..SENSOR
    });
    assert_eq!(
        too_long,
        (
            "stuck_after_seconds",
            Problem::TooManySamples { limit: u16::MAX }
        )
    );
    assert_eq!(
        Settings::from_sensor(&SensorSettings {
            stuck_after_seconds: 65.6,
            ..SENSOR
        })
        .unwrap_err()
        .to_string(),
        "stuck_after_seconds: more than 65535 samples at the sample rate given"
    );
    let negative_rate = Settings {
        sample_rate_hz: -1.0,
        ..Settings::DEFAULT
    };
    assert_eq!(
        negative_rate.validate().unwrap_err().field,
        "sample_rate_hz"
    );
}
