//! `gyrodrift import rosbag` and `gyrodrift export ros2`: a simulated series written here as ROS 2
//! bags (one per activation, one `sensor_msgs/msg/Imu` and one `sensor_msgs/msg/Temperature` per
//! sample, with the standard definitions in rosbag2's layout; written with the `mcap` crate, not
//! through gyrodrift) imports back to the same samples and off-times; a bag folder split into two
//! files is one activation; bags that are not what the options say are refused, naming the file,
//! the topic and the message, and leave nothing; and what `export ros2` writes (one message per
//! sample) imports back to the recording it came from.

use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;

use drift_recording::cdr::Encoder;
use drift_recording::ros2::{IMU_DEFINITION, TEMPERATURE_DEFINITION};
use drift_recording::{read_campaign_dir, read_recording, Recording, Segment};

mod common;

use common::{gyrodrift, ok};

/// Unix time of the bags' clock origin, ns: header stamps as a real driver writes them.
const EPOCH_NS: u64 = 1_700_000_000_000_000_000;

/// How a test bag is written.
#[derive(Clone, Copy)]
struct Bag<'a> {
    imu_schema: (&'a str, &'a str),
    imu_encodings: (&'a str, &'a str),
    /// Log time = header stamp + this (the recorder's receive delay), ns.
    receive_delay_ns: u64,
    /// Swap the header stamps of samples 5 and 6.
    swap_stamps: bool,
    /// From sample `.0` on, header stamps this much earlier, ns (a driver clock set back).
    header_back: (usize, u64),
    /// From sample `.0` on, log times this much earlier, ns (a bag merged out of order).
    log_back: (usize, u64),
    /// `angular_velocity_covariance[0]`.
    rate_covariance: f64,
    /// Odd gyro messages from a second sensor (`header.frame_id` `imu2_link`).
    two_frames: bool,
    /// The temperature messages' `header.frame_id`.
    temperature_frame: &'a str,
}

const STANDARD: Bag<'static> = Bag {
    imu_schema: ("sensor_msgs/msg/Imu", IMU_DEFINITION),
    imu_encodings: ("ros2msg", "cdr"),
    receive_delay_ns: 3_000_000,
    swap_stamps: false,
    header_back: (usize::MAX, 0),
    log_back: (usize::MAX, 0),
    rate_covariance: 0.001,
    two_frames: false,
    temperature_frame: "imu_link",
};

fn imu(e: &mut Encoder, t: u64, w: [f64; 3], frame: &str, covariance: f64) -> Vec<u8> {
    let e = e.begin();
    e.i32((t / 1_000_000_000) as i32)
        .u32((t % 1_000_000_000) as u32)
        .string(frame);
    for v in [0.0, 0.0, 0.0, 1.0] {
        e.f64(v);
    }
    for k in 0..9 {
        e.f64(if k == 0 { -1.0 } else { 0.0 });
    }
    e.f64(w[0]).f64(w[1]).f64(w[2]);
    e.f64(covariance);
    for _ in 1..9 {
        e.f64(0.001);
    }
    e.f64(0.1).f64(0.2).f64(9.81);
    for _ in 0..9 {
        e.f64(0.0);
    }
    e.bytes().to_vec()
}

fn temperature(e: &mut Encoder, t: u64, celsius: f64, frame: &str) -> Vec<u8> {
    e.begin()
        .i32((t / 1_000_000_000) as i32)
        .u32((t % 1_000_000_000) as u32)
        .string(frame)
        .f64(celsius)
        .f64(0.0)
        .bytes()
        .to_vec()
}

/// Writes samples `range` of `s` as a ROS 2 bag file at `path`: per sample an Imu (rad/s) and a
/// Temperature (the X axis's °C), stamped on the segment's clock from [`EPOCH_NS`], plus a
/// `/rosout`-like topic the import ignores.
fn write_bag(path: &Path, s: &Segment, range: std::ops::Range<usize>, how: Bag<'_>) {
    let file = std::fs::File::create(path).unwrap();
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .create(BufWriter::new(file))
        .unwrap();
    let none = BTreeMap::new();
    let imu_schema = w
        .add_schema(
            how.imu_schema.0,
            how.imu_encodings.0,
            how.imu_schema.1.as_bytes(),
        )
        .unwrap();
    let temperature_schema = w
        .add_schema(
            "sensor_msgs/msg/Temperature",
            "ros2msg",
            TEMPERATURE_DEFINITION.as_bytes(),
        )
        .unwrap();
    let log_schema = w
        .add_schema("std_msgs/msg/String", "ros2msg", b"string data")
        .unwrap();
    let imu_channel = w
        .add_channel(imu_schema, "/imu/data", how.imu_encodings.1, &none)
        .unwrap();
    let temperature_channel = w
        .add_channel(temperature_schema, "/imu/temperature", "cdr", &none)
        .unwrap();
    let log_channel = w.add_channel(log_schema, "/rosout", "cdr", &none).unwrap();
    let period = 1_000_000_000 / u64::from(s.sample_rate_hz);
    let mut e = Encoder::default();
    for i in range {
        let mut stamp = EPOCH_NS + s.power_on_ns + i as u64 * period;
        if how.swap_stamps && (i == 5 || i == 6) {
            stamp = if i == 5 {
                stamp + period
            } else {
                stamp - period
            };
        }
        let back = |(from, ns): (usize, u64)| if i >= from { ns } else { 0 };
        stamp -= back(how.header_back);
        let log = EPOCH_NS + s.power_on_ns + i as u64 * period + how.receive_delay_ns
            - back(how.log_back);
        let header = |channel_id: u16, sequence: u32| mcap::records::MessageHeader {
            channel_id,
            sequence,
            log_time: log,
            publish_time: log,
        };
        let rates = [0, 1, 2].map(|a| f64::from(s.rate_dps[a][i]).to_radians());
        let frame = if how.two_frames && i % 2 == 1 {
            "imu2_link"
        } else {
            "imu_link"
        };
        w.write_to_known_channel(
            &header(imu_channel, i as u32),
            &imu(&mut e, stamp, rates, frame, how.rate_covariance),
        )
        .unwrap();
        let celsius = f64::from(s.temperature_raw[0][i]) / 200.0;
        w.write_to_known_channel(
            &header(temperature_channel, i as u32),
            &temperature(&mut e, stamp, celsius, how.temperature_frame),
        )
        .unwrap();
        if i % 50 == 0 {
            let mut text = Encoder::default();
            text.begin().string("log line");
            w.write_to_known_channel(&header(log_channel, i as u32), text.bytes())
                .unwrap();
        }
    }
    w.finish().unwrap();
}

fn simulate(dir: &Path) -> Recording {
    std::fs::write(
        dir.join("c.toml"),
        "seed = 5\nunits = 1\nsample_rate_hz = 100\nset_points_celsius = [30]\n[protocol]\nintervals_min = [1]\nrepeats = 1\nactivation_s = 20\n",
    )
    .unwrap();
    let sim = dir.join("sim");
    ok(&[
        "simulate",
        "-q",
        "--campaign",
        dir.join("c.toml").to_str().unwrap(),
        "-o",
        sim.to_str().unwrap(),
    ]);
    read_campaign_dir(&sim).unwrap().remove(0)
}

/// The off-time before each activation after the first on the recording clock, s.
fn off_times(r: &Recording) -> Vec<f64> {
    r.segments
        .windows(2)
        .map(|w| {
            let end = w[0].power_on_ns + w[0].len() as u64 * 1_000_000_000 / 100;
            (w[1].power_on_ns - end) as f64 * 1e-9
        })
        .collect()
}

/// The imported recording has the original's activations: samples (rates to the f32 rounding of
/// the rad/s conversion, temperatures exactly), switch-on times relative to the first and
/// off-times.
fn assert_same_samples(original: &Recording, back: &Recording) {
    assert_eq!(back.segments.len(), original.segments.len());
    let origin = original.segments[0].power_on_ns;
    for (k, (a, b)) in original.segments.iter().zip(&back.segments).enumerate() {
        assert_eq!(b.labels.activation as usize, k + 1);
        assert_eq!(a.len(), b.len(), "activation {k}");
        assert_eq!(b.power_on_ns, a.power_on_ns - origin, "activation {k}");
        for axis in 0..3 {
            assert_eq!(a.temperature_raw[0], b.temperature_raw[axis], "one sensor");
            for (x, y) in a.rate_dps[axis].iter().zip(&b.rate_dps[axis]) {
                assert!((x - y).abs() <= 1e-6 * x.abs().max(1e-3), "{x} vs {y}");
            }
        }
    }
    assert_eq!(back.segments[0].labels.off_before_s, None);
    let expected = off_times(original);
    assert!(expected.iter().all(|&s| s > 50.0), "{expected:?}");
    for (b, off) in back.segments[1..].iter().zip(expected) {
        let got = b.labels.off_before_s.unwrap();
        assert!((got - off).abs() < 1e-9, "{got} vs {off}");
    }
}

#[test]
fn a_simulated_series_written_as_ros2_bags_imports_back() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let original = simulate(d);
    assert_eq!(original.segments.len(), 5);
    let bags = d.join("bags");
    std::fs::create_dir(&bags).unwrap();
    for (k, s) in original.segments.iter().enumerate() {
        if k == 2 {
            // A bag folder split into two files, as rosbag2 splits by size.
            let folder = bags.join("run_c");
            std::fs::create_dir(&folder).unwrap();
            std::fs::write(
                folder.join("metadata.yaml"),
                "rosbag2_bagfile_information:\n",
            )
            .unwrap();
            write_bag(&folder.join("run_c_0.mcap"), s, 0..700, STANDARD);
            write_bag(&folder.join("run_c_1.mcap"), s, 700..s.len(), STANDARD);
        } else {
            // Named against their order in time: the import orders by start time.
            write_bag(
                &bags.join(format!("run_{}.mcap", ["e", "d", "", "b", "a"][k])),
                s,
                0..s.len(),
                STANDARD,
            );
        }
    }
    let out = d.join("imported");
    let text = ok(&[
        "import",
        "rosbag",
        bags.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--gyro-topic",
        "/imu/data",
        "--temperature-topic",
        "/imu/temperature",
        "--set-point",
        "30",
        "--series-kind",
        "protocol",
        "--unit-id",
        "bench",
    ]);
    assert!(text.contains("bench.mcap: 5 activations"), "{text}");
    let back = read_recording(&out.join("recordings/bench.mcap")).unwrap();
    assert_eq!(back.metadata["set_point_celsius"], "30");
    assert_same_samples(&original, &back);
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("import.json")).unwrap()).unwrap();
    let third = &manifest["bags"][2];
    assert!(third["bag"].as_str().unwrap().ends_with("run_c"), "{third}");
    assert_eq!(third["files"].as_array().unwrap().len(), 2);
    assert_eq!(third["gyro_messages"], 2000);

    // One bag alone: one activation, no off-time. By log time (3 ms after each stamp) the samples
    // are the same, on a clock 3 ms later.
    let one = d.join("one");
    ok(&[
        "import",
        "ros2",
        bags.join("run_d.mcap").to_str().unwrap(),
        "-o",
        one.to_str().unwrap(),
        "--timestamps",
        "log",
    ]);
    let r = read_recording(&one.join("recordings/ros2.mcap")).unwrap();
    assert_eq!(r.segments.len(), 1);
    assert_eq!(r.segments[0].rate_dps, back.segments[1].rate_dps);
    assert_eq!(r.segments[0].labels.off_before_s, None);
}

fn import_fails(bag: &Path, out: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "import",
        "rosbag",
        bag.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (status, text) = gyrodrift(&args);
    assert_eq!(status.status.code(), Some(2), "{text}");
    assert!(!out.exists(), "a failed import left {}", out.display());
    let left: Vec<_> = std::fs::read_dir(out.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("importing"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    text
}

/// Imports `bag` into `out` by the recorder's log times, which must succeed; the recording written.
fn import_by_log_time(bag: &Path, out: &Path) -> Recording {
    ok(&[
        "import",
        "rosbag",
        bag.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--timestamps",
        "log",
    ]);
    read_recording(&out.join("recordings/ros2.mcap")).unwrap()
}

#[test]
fn bags_that_are_not_what_the_options_say_are_refused_by_file_topic_and_message() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let original = simulate(d);
    let s = &original.segments[0];
    let out = d.join("out");
    let good = d.join("good.mcap");
    write_bag(&good, s, 0..300, STANDARD);
    // A topic the bag does not have: the bag's topics are listed.
    let text = import_fails(&good, &out, &["--gyro-topic", "/imu/raw"]);
    assert!(
        text.contains("good.mcap: topic /imu/raw: no messages; the bag's topics: /imu/data (sensor_msgs/msg/Imu), /imu/temperature (sensor_msgs/msg/Temperature), /rosout (std_msgs/msg/String); name the right one with `--gyro-topic`"),
        "{text}"
    );
    // The temperature topic named as the gyro topic.
    let text = import_fails(&good, &out, &["--gyro-topic", "/imu/temperature"]);
    assert!(
        text.contains("good.mcap: topic /imu/temperature: schema `sensor_msgs/msg/Temperature` (ros2msg, cdr messages), expected sensor_msgs/msg/Imu"),
        "{text}"
    );
    // A custom message under the standard name: single-precision angular velocity.
    let custom = IMU_DEFINITION.replace(
        "geometry_msgs/Vector3 angular_velocity\n",
        "float32[3] angular_velocity\n",
    );
    let bag = d.join("custom.mcap");
    write_bag(
        &bag,
        s,
        0..300,
        Bag {
            imu_schema: ("sensor_msgs/msg/Imu", &custom),
            ..STANDARD
        },
    );
    let text = import_fails(&bag, &out, &[]);
    assert!(
        text.contains("custom.mcap: topic /imu/data: schema `sensor_msgs/msg/Imu`: its definition is not the standard one: wire field #8 is `float32[3] angular_velocity`, the standard sensor_msgs/msg/Imu has `float64 angular_velocity.x`"),
        "{text}"
    );
    // Another encoding (a ROS 1 bag converted to MCAP).
    let bag = d.join("ros1.mcap");
    write_bag(
        &bag,
        s,
        0..300,
        Bag {
            imu_schema: ("sensor_msgs/Imu", IMU_DEFINITION),
            imu_encodings: ("ros1msg", "ros1"),
            ..STANDARD
        },
    );
    let text = import_fails(&bag, &out, &[]);
    assert!(
        text.contains("ros1.mcap: topic /imu/data: schema encoding `ros1msg` with `ros1` messages, but only ROS 2's `ros2msg` with `cdr` is read (a ROS 1 bag: convert it to ROS 2 first"),
        "{text}"
    );
    // Header stamps that go back: the message and the fix.
    let bag = d.join("stamps.mcap");
    write_bag(
        &bag,
        s,
        0..300,
        Bag {
            swap_stamps: true,
            ..STANDARD
        },
    );
    let text = import_fails(&bag, &out, &[]);
    assert!(
        text.contains("stamps.mcap: topic /imu/data, message #6: header.stamp 1700003600.050000000 s is not after the previous message's (1700003600.060000000 s)")
            && text.contains("import with `--timestamps log`"),
        "{text}"
    );
    // By log time the same bag imports.
    import_by_log_time(&bag, &out);
    std::fs::remove_dir_all(&out).unwrap();
    // A bag cut short.
    let bytes = std::fs::read(&good).unwrap();
    let cut = d.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let text = import_fails(&cut, &out, &[]);
    assert!(text.contains("cut.mcap: MCAP: truncated"), "{text}");
    // Two bags that follow each other without a power-off.
    let folder = d.join("back_to_back");
    std::fs::create_dir(&folder).unwrap();
    write_bag(&folder.join("a.mcap"), s, 0..300, STANDARD);
    write_bag(&folder.join("b.mcap"), s, 300..600, STANDARD);
    let text = import_fails(&folder, &out, &[]);
    assert!(
        text.contains("b.mcap starts 0.010000 s after the last message of")
            && text.contains("put the files of one power-on into one bag folder"),
        "{text}"
    );
    // What the messages say about themselves: rates not provided (REP-145), two sensors on one
    // topic (also by log time, which the header's error used to suggest), a temperature of
    // another sensor.
    let bag = d.join("unknown.mcap");
    write_bag(
        &bag,
        s,
        0..300,
        Bag {
            rate_covariance: -1.0,
            ..STANDARD
        },
    );
    let text = import_fails(&bag, &out, &[]);
    assert!(
        text.contains(
            "unknown.mcap: topic /imu/data, message #0: angular_velocity_covariance[0] is −1"
        ) && text.contains("REP-145"),
        "{text}"
    );
    let bag = d.join("two.mcap");
    write_bag(
        &bag,
        s,
        0..300,
        Bag {
            two_frames: true,
            ..STANDARD
        },
    );
    for clock in ["header", "log"] {
        let text = import_fails(&bag, &out, &["--timestamps", clock]);
        assert!(
            text.contains("two.mcap: topic /imu/data, message #1: header.frame_id `imu2_link` differs from the topic's first message's `imu_link`: two sensors"),
            "{text}"
        );
    }
    let bag = d.join("other.mcap");
    write_bag(
        &bag,
        s,
        0..300,
        Bag {
            temperature_frame: "board_link",
            ..STANDARD
        },
    );
    let text = import_fails(&bag, &out, &[]);
    assert!(
        text.contains("other.mcap: topic /imu/temperature: header.frame_id `board_link` is not the gyro's (`imu_link` on /imu/data)")
            && text.contains("--any-temperature-frame"),
        "{text}"
    );
    ok(&[
        "import",
        "rosbag",
        bag.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--any-temperature-frame",
    ]);
    std::fs::remove_dir_all(&out).unwrap();
    // A grid faster than the messages: refused unless asked for.
    let text = import_fails(&good, &out, &["--rate-hz", "1000"]);
    assert!(
        text.contains("topic /imu/data has 100.0 messages per second, and a grid of 1000 Hz would make up 90 % of its samples")
            && text.contains("`--rate-hz 100`"),
        "{text}"
    );
    ok(&[
        "import",
        "rosbag",
        good.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--rate-hz",
        "1000",
        "--upsample",
    ]);
    std::fs::remove_dir_all(&out).unwrap();
    // Compressed by rosbag2: a compressed file, and compressed messages.
    let folder = d.join("zstd");
    std::fs::create_dir(&folder).unwrap();
    std::fs::write(
        folder.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n",
    )
    .unwrap();
    std::fs::write(
        folder.join("zstd_0.mcap.zstd"),
        [0x28, 0xb5, 0x2f, 0xfd, 0, 0],
    )
    .unwrap();
    let text = import_fails(&folder, &out, &[]);
    assert!(
        text.contains("zstd_0.mcap.zstd: MCAP: a zstd-compressed file"),
        "{text}"
    );
    let squeezed = d.join("squeezed.mcap");
    {
        let mut w = mcap::WriteOptions::new()
            .profile("ros2")
            .create(BufWriter::new(std::fs::File::create(&squeezed).unwrap()))
            .unwrap();
        let schema = w
            .add_schema("sensor_msgs/msg/Imu", "ros2msg", IMU_DEFINITION.as_bytes())
            .unwrap();
        let channel = w
            .add_channel(schema, "/imu/data", "cdr", &BTreeMap::new())
            .unwrap();
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: 0,
            log_time: 1,
            publish_time: 1,
        };
        w.write_to_known_channel(&header, &[0x28, 0xb5, 0x2f, 0xfd, 1, 2, 3])
            .unwrap();
        w.finish().unwrap();
    }
    let text = import_fails(&squeezed, &out, &[]);
    assert!(
        text.contains("squeezed.mcap: topic /imu/data, message #0: a zstd-compressed message"),
        "{text}"
    );
    // A gap in the gyro messages beyond --max-gap, named by bag, topic and message.
    let text = import_fails(&good, &out, &["--max-gap", "0.001"]);
    assert!(
        text.contains("good.mcap: topic /imu/data (temperature from /imu/temperature), message ")
            && text.contains(", field `header.stamp`: gap: ")
            && text.contains("since the previous message (at most 0.001 s); `--max-gap <s>`")
            && !text.contains("row"),
        "{text}"
    );
}

/// A header clock set back by more than a second mid-bag (a driver that restarted at boot) while
/// the recorder's log times increase: refused, naming the restart and `--timestamps log`, by which
/// the bag imports whole.
#[test]
fn a_header_clock_that_restarts_is_refused_pointing_to_log_times() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let original = simulate(d);
    let s = &original.segments[0];
    let out = d.join("out");
    let bag = d.join("restart.mcap");
    write_bag(
        &bag,
        s,
        0..300,
        Bag {
            header_back: (150, 30_000_000_000),
            ..STANDARD
        },
    );
    let text = import_fails(&bag, &out, &[]);
    assert!(
        text.contains("restart.mcap: topic /imu/data, message #150: header.stamp 1700003571.500000000 s is not after the previous message's (1700003601.490000000 s)")
            && text.contains("the driver's clock went back (it restarts at boot, or was set): import with `--timestamps log`"),
        "{text}"
    );
    let r = import_by_log_time(&bag, &out);
    assert_eq!(r.segments.len(), 1);
    assert_eq!(r.segments[0].len(), 300);
}

/// Header stamps and log times that both go back, at one message or at two: refused by either
/// clock, saying neither increases, and sending the user to neither `--timestamps` (the other
/// clock fails too, even where it goes back only after this clock did).
#[test]
fn a_bag_whose_two_clocks_go_back_sends_the_user_to_neither() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let original = simulate(d);
    let s = &original.segments[0];
    let out = d.join("out");
    let back = 30_000_000_000;
    let together = d.join("together.mcap");
    write_bag(
        &together,
        s,
        0..300,
        Bag {
            header_back: (150, back),
            log_back: (150, back),
            ..STANDARD
        },
    );
    let apart = d.join("apart.mcap");
    write_bag(
        &apart,
        s,
        0..300,
        Bag {
            header_back: (200, back),
            log_back: (100, back),
            ..STANDARD
        },
    );
    for (bag, clock, at) in [
        (&together, "header", "message #150: header.stamp"),
        (&together, "log", "message #150: log time"),
        (&apart, "header", "message #200: header.stamp"),
        (&apart, "log", "message #100: log time"),
    ] {
        let text = import_fails(bag, &out, &["--timestamps", clock]);
        assert!(
            text.contains(&format!("topic /imu/data, {at} "))
                && text.contains(
                    "neither the header stamps nor the recorder's log times increase here"
                )
                && !text.contains("--timestamps"),
            "{clock}: {text}"
        );
    }
}

#[test]
fn an_exported_recording_has_a_message_per_sample_and_imports_back() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let original = simulate(d);
    let samples: usize = original.segments.iter().map(Segment::len).sum();
    // One file: per sample an Imu and a Temperature per axis.
    let file = d.join("all.mcap");
    let text = ok(&[
        "export",
        "ros2",
        original.path.to_str().unwrap(),
        "-o",
        file.to_str().unwrap(),
    ]);
    assert!(text.contains(&format!("{samples} samples")), "{text}");
    let bytes = std::fs::read(&file).unwrap();
    let summary = mcap::read::Summary::read(&bytes).unwrap().unwrap();
    let stats = summary.stats.unwrap();
    assert_eq!(stats.message_count, 4 * samples as u64);
    let mut topics: Vec<(String, String)> = summary
        .channels
        .values()
        .map(|c| {
            (
                c.topic.clone(),
                c.schema.as_ref().map(|s| s.name.clone()).unwrap(),
            )
        })
        .collect();
    topics.sort();
    assert_eq!(
        topics,
        [
            ("/imu/data", "sensor_msgs/msg/Imu"),
            ("/imu/temperature", "sensor_msgs/msg/Temperature"),
            ("/imu/temperature/y", "sensor_msgs/msg/Temperature"),
            ("/imu/temperature/z", "sensor_msgs/msg/Temperature"),
        ]
        .map(|(a, b)| (a.to_owned(), b.to_owned()))
    );
    // The single file re-imports: the labels it carries split it into its activations.
    let from_file = d.join("from-file");
    ok(&[
        "import",
        "rosbag",
        file.to_str().unwrap(),
        "-o",
        from_file.to_str().unwrap(),
    ]);
    let name = format!("recordings/{}.mcap", original.unit_id);
    let back = read_recording(&from_file.join(&name)).unwrap();
    assert_round_trip(&original, &back);
    // A folder: one rosbag2 bag folder per activation (metadata.yaml with the type hashes).
    let bags = d.join("bags");
    ok(&[
        "export",
        "ros2",
        original.path.to_str().unwrap(),
        "-o",
        bags.to_str().unwrap(),
    ]);
    let yaml = std::fs::read_to_string(bags.join("activation-005/metadata.yaml")).unwrap();
    assert!(
        yaml.contains("relative_file_paths:\n    - activation-005_0.mcap")
            && yaml.contains(drift_recording::ros2::IMU_TYPE_HASH)
            && yaml.contains(drift_recording::ros2::TEMPERATURE_TYPE_HASH),
        "{yaml}"
    );
    let out = d.join("back");
    ok(&[
        "import",
        "rosbag",
        bags.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let back = read_recording(&out.join(&name)).unwrap();
    assert_round_trip(&original, &back);
    // The second pass is byte-stable: exporting the import and importing that again gives the
    // same bags and the same recording.
    let bags2 = d.join("bags2");
    let out2 = d.join("back2");
    let bags3 = d.join("bags3");
    for (from, to, verb) in [
        (out.join(&name), bags2.clone(), "export"),
        (bags2.clone(), out2.clone(), "import"),
        (out2.join(&name), bags3.clone(), "export"),
    ] {
        let mut args = vec![verb, if verb == "export" { "ros2" } else { "rosbag" }];
        args.extend([from.to_str().unwrap(), "-o", to.to_str().unwrap()]);
        ok(&args);
    }
    for k in 1..=original.segments.len() {
        let bag = format!("activation-{k:03}/activation-{k:03}_0.mcap");
        assert!(
            std::fs::read(bags2.join(&bag)).unwrap() == std::fs::read(bags3.join(&bag)).unwrap(),
            "{bag} differs on the second pass"
        );
    }
    assert_eq!(
        read_recording(&out2.join(&name)).unwrap().segments,
        back.segments
    );
    // Exporting into an earlier export is refused unless --force.
    let (status, text) = gyrodrift(&[
        "export",
        "ros2",
        original.path.to_str().unwrap(),
        "-o",
        bags.to_str().unwrap(),
    ]);
    assert_eq!(status.status.code(), Some(2), "{text}");
    assert!(
        text.contains("pass --force to replace the export there"),
        "{text}"
    );
}

/// An export imported back keeps the recording's unit, rate, set point and kind, and each
/// activation's labels, switch-on time, rates (to the f32 rounding of rad/s) and per-axis
/// temperatures.
fn assert_round_trip(original: &Recording, back: &Recording) {
    assert_eq!(back.unit_id, original.unit_id);
    assert_eq!(back.sample_rate_hz, original.sample_rate_hz);
    for key in [
        "set_point_celsius",
        "series_kind",
        "unit_id",
        "sample_rate_hz",
    ] {
        assert_eq!(
            back.metadata
                .get(key)
                .map(|v| v.parse::<f64>().map_or(v.clone(), |f| f.to_string())),
            original
                .metadata
                .get(key)
                .map(|v| v.parse::<f64>().map_or(v.clone(), |f| f.to_string())),
            "{key}"
        );
    }
    assert_eq!(back.segments.len(), original.segments.len());
    for (k, (a, b)) in original.segments.iter().zip(&back.segments).enumerate() {
        assert_eq!(b.labels, a.labels, "activation {k}");
        assert_eq!(b.power_on_ns, a.power_on_ns, "activation {k}");
        assert_eq!(b.temperature_raw, a.temperature_raw, "activation {k}");
        for axis in 0..3 {
            for (x, y) in a.rate_dps[axis].iter().zip(&b.rate_dps[axis]) {
                assert!((x - y).abs() <= 1e-6 * x.abs().max(1e-3), "{x} vs {y}");
            }
        }
    }
}
