//! `gyrodrift export ros2`: a recording → ROS 2 bags with one standard message per sample
//! (`gyrodrift export image`, firmware images per unit: `export_image`).
//!
//! The recording format batches 100 samples per message, which ROS tools and Foxglove plot as one
//! point per message. The export writes one `sensor_msgs/msg/Imu` per sample (`angular_velocity`,
//! rad/s) and one `sensor_msgs/msg/Temperature` per sample and axis (°C), stamped with the
//! sample's time on the recording clock (`drift_recording::ros2::write_ros2_bag`), and a metadata
//! record with the recording's labels. Output: one `.mcap` file with every activation, or a new
//! folder with one bag folder per activation (`metadata.yaml` and its `.mcap` file, as rosbag2
//! writes them). `gyrodrift import rosbag` reads either back to the recording's unit, rate, set
//! point, kind, series and off-times.

use std::path::{Path, PathBuf};

use drift_recording::output_folder::{Owned, Writer};
use drift_recording::read_recording;
use drift_recording::ros2::{write_ros2_bag, write_ros2_bag_folder, ExportSource, ExportTopics};

/// Options of `gyrodrift export`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The target format.
    #[command(subcommand)]
    pub format: Format,
}

/// Target formats.
#[derive(Debug, clap::Subcommand)]
pub enum Format {
    /// ROS 2 bags (rosbag2's MCAP storage): `sensor_msgs/msg/Imu` and `sensor_msgs/msg/Temperature`,
    /// one message per sample.
    #[command(visible_alias = "rosbag")]
    Ros2(Ros2Args),
    /// Firmware images, one per unit, from a tables folder: `<unit>.bin`, `manifest.json` and,
    /// with `--address`, Intel HEX.
    Image(super::export_image::ImageArgs),
}

/// Options of `gyrodrift export ros2`.
#[derive(Debug, clap::Args)]
pub struct Ros2Args {
    /// One recording (`.mcap` of the gyrodrift format, e.g. `<campaign>/recordings/<name>.mcap`).
    pub recording: PathBuf,
    /// Output: a `.mcap` file (every activation in one bag), or a new folder with one bag folder
    /// per activation (`activation-001/` with `metadata.yaml` and `activation-001_0.mcap`, ...).
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Replace an earlier `gyrodrift export` output in the output folder, whole; or the `.mcap`
    /// file named by `--out`.
    #[arg(long)]
    pub force: bool,
    /// The `sensor_msgs/msg/Imu` topic.
    #[arg(long, default_value = "/imu/data")]
    pub gyro_topic: String,
    /// The `sensor_msgs/msg/Temperature` topic of the X axis's sensor; the Y and Z axes' are
    /// `<topic>/y` and `<topic>/z`.
    #[arg(long, default_value = "/imu/temperature")]
    pub temperature_topic: String,
}

/// `export` as a writer of output folders.
pub const WRITER: Writer = Writer {
    command: "export",
    product: "export",
    doing: "exporting",
    owned: Owned::Marker,
};

/// Runs `gyrodrift export`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    match &args.format {
        Format::Ros2(ros2) => run_ros2(ros2),
        Format::Image(image) => super::export_image::run(image),
    }
}

fn run_ros2(args: &Ros2Args) -> anyhow::Result<()> {
    anyhow::ensure!(
        !args.recording.is_dir(),
        "{}: a folder; give one recording file (a campaign folder holds one per unit, set point and series kind under recordings/)",
        args.recording.display()
    );
    for (option, topic) in [
        ("--gyro-topic", &args.gyro_topic),
        ("--temperature-topic", &args.temperature_topic),
    ] {
        anyhow::ensure!(
            topic.starts_with('/') && topic.len() > 1 && !topic.ends_with('/'),
            "option `{option}`: `{topic}` is not a ROS topic name (expected e.g. /imu/data)"
        );
    }
    let recording = read_recording(&args.recording)?;
    let topics = ExportTopics {
        imu: args.gyro_topic.clone(),
        temperature: args.temperature_topic.clone(),
    };
    let samples: usize = recording.segments.iter().map(|s| s.len()).sum();
    let source = ExportSource {
        unit_id: &recording.unit_id,
        sample_rate_hz: recording.sample_rate_hz,
        metadata: &recording.metadata,
    };
    if args.out.extension().is_some_and(|e| e == "mcap") {
        refuse_existing_file(args)?;
        // The bag is written to a temporary beside it: an interruption removes that.
        let parent = args.out.parent().filter(|p| !p.as_os_str().is_empty());
        super::interrupt::watch(parent.unwrap_or(Path::new(".")));
        let segments: Vec<_> = recording.segments.iter().collect();
        let bytes = write_ros2_bag(&args.out, &segments, source, &topics)?.bytes;
        println!(
            "{}: {} activations, {samples} samples → {} (per sample one message on {} and on each of {}; {bytes} bytes)",
            args.recording.display(),
            segments.len(),
            args.out.display(),
            topics.imu,
            topics.temperature_axes().join(", ")
        );
        return Ok(());
    }
    let staged = super::interrupt::stage(&args.out, args.force, &WRITER)?;
    let written = write_folder(staged.path(), &recording.segments, source, &topics)?;
    staged.commit()?;
    let bytes = written;
    println!(
        "{}: {} activations, {samples} samples → {} bags in {} ({bytes} bytes)",
        args.recording.display(),
        recording.segments.len(),
        recording.segments.len(),
        args.out.display()
    );
    Ok(())
}

/// A single-file output replaces an existing file only with `--force`, and never the recording it
/// is made from or a folder (a bag folder, say, whose name ends in `.mcap`).
fn refuse_existing_file(args: &Ros2Args) -> anyhow::Result<()> {
    let out = &args.out;
    anyhow::ensure!(
        !out.is_dir(),
        "{}: a folder; give a new `.mcap` file name, or a folder name without `.mcap` for one bag folder per activation",
        out.display()
    );
    if !out.exists() {
        return Ok(());
    }
    let same = std::fs::canonicalize(out).ok() == std::fs::canonicalize(&args.recording).ok();
    anyhow::ensure!(
        !same,
        "{}: the recording being exported; give another output file",
        out.display()
    );
    anyhow::ensure!(
        args.force,
        "{}: the file exists; pass --force to replace it, or choose a new file",
        out.display()
    );
    Ok(())
}

fn write_folder(
    folder: &Path,
    segments: &[drift_recording::Segment],
    source: ExportSource<'_>,
    topics: &ExportTopics,
) -> anyhow::Result<u64> {
    let mut bytes = 0;
    for (k, segment) in segments.iter().enumerate() {
        let path = folder.join(format!("activation-{:03}", k + 1));
        bytes += write_ros2_bag_folder(&path, &[segment], source, topics)?;
    }
    Ok(bytes)
}
