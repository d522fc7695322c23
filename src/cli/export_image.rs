//! `gyrodrift export image`: a tables folder → one firmware image per unit, ready to flash, with a
//! manifest and, at a given flash address, Intel HEX.
//!
//! Each unit's image is `<tables>/<unit>/<model>.bin` decoded (so a damaged or foreign file is
//! refused before anything is written) and written as `<out>/<unit>.bin`; its header names the
//! unit (an image that names none, written without, is stamped with its folder's unit), and an
//! image that names another unit than its folder's is refused, naming both. `manifest.json` lists
//! per unit the file, its length and CRC-32, the capacities the tables need, the tool version and
//! the date, so a production line can check what it flashes.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use drift_core::blob::{self, Header, Image};
use drift_core::{ModifiedTables, PolynomialTables, RecommendedTables, RelativePolynomialTables};
use drift_evaluate::tables_folder;
use drift_recording::output_folder::{Owned, Writer};

use super::check::Stored;

/// `export image` as a writer of output folders.
pub const WRITER: Writer = Writer {
    command: "export image",
    product: "export",
    doing: "exporting",
    owned: Owned::Marker,
};

/// Options of `gyrodrift export image`.
#[derive(Debug, clap::Args)]
pub struct ImageArgs {
    /// Folder of fitted tables, one subfolder per unit (what `gyrodrift fit` writes).
    pub tables: PathBuf,
    /// Which stored model to export.
    #[arg(long, value_enum, default_value = "recommended")]
    pub model: Stored,
    /// Output: a new folder with `<unit>.bin` per unit and `manifest.json`.
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Also write `<unit>.hex` (Intel HEX) placing the image at this flash address (e.g.
    /// `0x08060000`, the start of the sector the firmware reads with `blob::image_len`).
    #[arg(long, value_parser = parse_address)]
    pub address: Option<u32>,
    /// Replace an earlier export in `--out` (only an export is ever replaced).
    #[arg(long)]
    pub force: bool,
}

fn parse_address(text: &str) -> Result<u32, String> {
    let parsed = match text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        Some(hex) => u32::from_str_radix(&hex.replace('_', ""), 16),
        None => text.replace('_', "").parse(),
    };
    parsed.map_err(|_| format!("`{text}` is not a 32-bit flash address (e.g. 0x08060000)"))
}

/// One unit's exported image.
#[derive(Debug, serde::Serialize)]
struct Entry {
    unit_id: String,
    image: String,
    hex: Option<String>,
    bytes: usize,
    crc32: String,
    format_version: u16,
    capacities: Option<blob::Capacities>,
    tool_version: String,
    date: u32,
    #[serde(skip)]
    files: Vec<(PathBuf, Vec<u8>)>,
}

/// Runs `gyrodrift export image`.
pub fn run(args: &ImageArgs) -> anyhow::Result<()> {
    // Refused before any reading: the one rule of every writer's output folder.
    drift_recording::output_folder::check(&args.out, args.force, "--force", &WRITER)?;
    let model = args.model.model();
    let mut units: Vec<String> = std::fs::read_dir(&args.tables)
        .with_context(|| format!("cannot read the tables folder {}", args.tables.display()))?
        .filter_map(Result::ok)
        .filter(|entry| entry.path().is_dir())
        .filter(|entry| entry.path().join(format!("{}.bin", model.stem())).is_file())
        .map(|entry| entry.file_name().to_string_lossy().into_owned())
        .collect();
    units.sort();
    if units.is_empty() {
        bail!(
            "{}: no unit folder holds {}.bin (a tables folder as `gyrodrift fit` writes it: <tables>/<unit>/{}.bin)",
            args.tables.display(),
            model.stem(),
            model.stem()
        );
    }
    let mut entries = Vec::with_capacity(units.len());
    for unit in &units {
        let path = model.image_path(&args.tables, unit);
        let entry = match args.model {
            Stored::Modified | Stored::ByHistory => export::<ModifiedTables>(&path, unit, args)?,
            Stored::Standard | Stored::ThirdOrder => export::<PolynomialTables>(&path, unit, args)?,
            Stored::Relative => export::<RelativePolynomialTables>(&path, unit, args)?,
            Stored::Recommended => export::<RecommendedTables>(&path, unit, args)?,
        };
        entries.push(entry);
    }
    let manifest = serde_json::json!({
        "model": model.stem(),
        "address": args.address.map(|a| format!("{a:#010x}")),
        "units": entries,
    });
    let mut files: Vec<(PathBuf, Vec<u8>)> = entries.into_iter().flat_map(|e| e.files).collect();
    files.push((
        PathBuf::from("manifest.json"),
        serde_json::to_string_pretty(&manifest)?.into_bytes(),
    ));
    write_folder(&args.out, args.force, &files)?;
    println!(
        "{} units' {} images → {} (manifest.json{})",
        units.len(),
        model.stem(),
        args.out.display(),
        if args.address.is_some() {
            ", Intel HEX"
        } else {
            ""
        }
    );
    Ok(())
}

/// Writes `files` (names in the folder) into a staging folder beside `out` that replaces it at the
/// end (an earlier export only with `force`): on any error `out` stays as it was.
fn write_folder(out: &Path, force: bool, files: &[(PathBuf, Vec<u8>)]) -> anyhow::Result<()> {
    let staged = super::interrupt::stage(out, force, &WRITER)?;
    let inside: Vec<_> = files
        .iter()
        .map(|(file, bytes)| (staged.path().join(file), bytes.clone()))
        .collect();
    tables_folder::write_files(&inside)?;
    staged.commit()?;
    Ok(())
}

/// Decodes `unit`'s image, stamps it with its unit if it names none, and encodes its files.
fn export<M: Image>(path: &Path, unit: &str, args: &ImageArgs) -> anyhow::Result<Entry> {
    let (model, mut header): (M, Header) = tables_folder::read_image_and_header(path)?;
    let owner = header.provenance.unit_id.as_str().to_owned();
    if !owner.is_empty() && owner != unit {
        bail!(
            "{}: this image is unit {owner}'s, but it sits in unit {unit}'s folder: each unit gets its own image",
            path.display()
        );
    }
    let mut bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    if owner.is_empty() || header.version != blob::FORMAT_VERSION {
        let provenance = if owner.is_empty() {
            tables_folder::provenance(unit).with_context(|| format!("unit folder {unit}"))?
        } else {
            header.provenance.clone()
        };
        bytes = tables_folder::image_bytes_for(&model, &provenance)
            .with_context(|| format!("re-encoding {}", path.display()))?;
        header = blob::header(&bytes)?;
    }
    let image_name = format!("{unit}.bin");
    let mut files = vec![(PathBuf::from(&image_name), bytes.clone())];
    let hex = match args.address {
        Some(address) => {
            let name = format!("{unit}.hex");
            files.push((
                PathBuf::from(&name),
                intel_hex(&bytes, address)?.into_bytes(),
            ));
            Some(name)
        }
        None => None,
    };
    let crc = bytes
        .last_chunk::<4>()
        .map_or(0, |tail| u32::from_le_bytes(*tail));
    Ok(Entry {
        unit_id: unit.to_owned(),
        image: image_name,
        hex,
        bytes: bytes.len(),
        crc32: format!("{crc:#010x}"),
        format_version: header.version,
        capacities: header.needs,
        tool_version: header.provenance.tool_version.as_str().to_owned(),
        date: header.provenance.date,
        files,
    })
}

/// `bytes` as Intel HEX (32-bit addresses) starting at `address`: 16 data bytes a record, an
/// extended linear address record wherever the upper 16 bits change.
fn intel_hex(bytes: &[u8], address: u32) -> anyhow::Result<String> {
    let end = u64::from(address) + bytes.len() as u64;
    if end > 1 << 32 {
        bail!("--address {address:#010x}: an image of {} bytes there ends past the 32-bit address space", bytes.len());
    }
    let mut records = Vec::new();
    let mut upper = None;
    let mut at = 0_usize;
    while at < bytes.len() {
        let here = address + at as u32;
        let high = (here >> 16) as u16;
        if upper != Some(high) {
            records.push(ihex::Record::ExtendedLinearAddress(high));
            upper = Some(high);
        }
        let room = 0x1_0000 - (here & 0xffff) as usize;
        let len = 16.min(room).min(bytes.len() - at);
        records.push(ihex::Record::Data {
            offset: (here & 0xffff) as u16,
            value: bytes[at..at + len].to_vec(),
        });
        at += len;
    }
    records.push(ihex::Record::EndOfFile);
    ihex::create_object_file_representation(&records).context("writing Intel HEX")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records cross a 64-KiB boundary with a new extended address and a checksum ihex's reader
    /// accepts; the bytes read back are the image's, at the address given.
    #[test]
    fn hex_places_the_bytes_at_the_address() {
        let bytes: Vec<u8> = (0..100_u8).collect();
        let text = intel_hex(&bytes, 0x0800_ffd8).unwrap();
        let mut read = Vec::new();
        let mut upper = 0_u32;
        for record in ihex::Reader::new(&text) {
            match record.unwrap() {
                ihex::Record::ExtendedLinearAddress(high) => upper = u32::from(high) << 16,
                ihex::Record::Data { offset, value } => {
                    let at = upper + u32::from(offset);
                    assert_eq!(at, 0x0800_ffd8 + read.len() as u32);
                    read.extend(value);
                }
                ihex::Record::EndOfFile => break,
                other => panic!("unexpected {other:?}"),
            }
        }
        assert_eq!(read, bytes);
        assert!(text.contains(":020000040801"), "{text}");
        assert!(intel_hex(&bytes, u32::MAX - 10).is_err());
        assert_eq!(parse_address("0x0806_0000"), Ok(0x0806_0000));
        assert!(parse_address("flash").unwrap_err().contains("`flash`"));
    }
}
