//! A small reader of PX4 ULog files (`.ulg`, format version 1): the definitions, the
//! subscriptions and their data messages, decoded field by field on request.
//!
//! What it reads: the header (magic, version, start timestamp), the flag bits and their appended
//! data offsets (a log with appended sections continues at each offset, the partial message
//! before it dropped, as PX4 and pyulog do), format definitions (scalar and array fields, nested
//! formats, `_padding` bytes, a format's trailing padding not logged), information messages, subscriptions (`A`) and data (`D`); parameters,
//! log strings, sync and dropout messages are skipped. Every error names the file and the byte
//! offset of the message at fault.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The ULog header's magic bytes.
const MAGIC: [u8; 7] = *b"ULog\x01\x12\x35";

/// A ULog file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum UlogError {
    /// File-system error.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not ULog or a message is malformed.
    #[error("{path}: byte {offset}: {reason}")]
    Format {
        /// The file.
        path: PathBuf,
        /// Byte offset of the message at fault.
        offset: usize,
        /// What is wrong.
        reason: String,
    },
}

/// A scalar field type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
    Bool,
    Char,
}

impl Scalar {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "int8_t" => Self::I8,
            "uint8_t" => Self::U8,
            "int16_t" => Self::I16,
            "uint16_t" => Self::U16,
            "int32_t" => Self::I32,
            "uint32_t" => Self::U32,
            "int64_t" => Self::I64,
            "uint64_t" => Self::U64,
            "float" => Self::F32,
            "double" => Self::F64,
            "bool" => Self::Bool,
            "char" => Self::Char,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 | Self::Bool | Self::Char => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::I64 | Self::U64 | Self::F64 => 8,
        }
    }

    fn read(self, b: &[u8]) -> Option<f64> {
        let a = |n: usize| b.get(..n);
        Some(match self {
            Self::I8 => f64::from(i8::from_le_bytes(a(1)?.try_into().ok()?)),
            Self::U8 | Self::Bool | Self::Char => f64::from(*b.first()?),
            Self::I16 => f64::from(i16::from_le_bytes(a(2)?.try_into().ok()?)),
            Self::U16 => f64::from(u16::from_le_bytes(a(2)?.try_into().ok()?)),
            Self::I32 => f64::from(i32::from_le_bytes(a(4)?.try_into().ok()?)),
            Self::U32 => f64::from(u32::from_le_bytes(a(4)?.try_into().ok()?)),
            Self::I64 => i64::from_le_bytes(a(8)?.try_into().ok()?) as f64,
            Self::U64 => u64::from_le_bytes(a(8)?.try_into().ok()?) as f64,
            Self::F32 => f64::from(f32::from_le_bytes(a(4)?.try_into().ok()?)),
            Self::F64 => f64::from_le_bytes(a(8)?.try_into().ok()?),
        })
    }
}

/// A flattened scalar field of a format: its name (`accel[1]`, `nested.x`), type and offset.
#[derive(Debug, Clone)]
struct Field {
    name: String,
    kind: Scalar,
    offset: usize,
}

/// One subscription (`A` message): a topic instance and its data messages, undecoded.
#[derive(Debug, Clone)]
pub struct UlogTopic {
    /// Topic name (`sensor_gyro`).
    pub name: String,
    /// Instance (`multi_id`): 0, 1, 2 for three gyros.
    pub instance: u8,
    fields: Vec<Field>,
    size: usize,
    messages: Vec<Vec<u8>>,
}

impl UlogTopic {
    /// Number of data messages.
    pub fn len(&self) -> usize {
        self.messages.len()
    }

    /// True if the topic has no data message.
    pub fn is_empty(&self) -> bool {
        self.messages.is_empty()
    }

    /// The flattened scalar field names (arrays as `name[i]`, nested formats as `outer.inner`).
    pub fn field_names(&self) -> impl Iterator<Item = &str> {
        self.fields.iter().map(|f| f.name.as_str())
    }

    /// One field over every message, as f64 (`None` if the topic has no such field).
    pub fn values(&self, field: &str) -> Option<Vec<f64>> {
        let f = self.fields.iter().find(|f| f.name == field)?;
        Some(
            self.messages
                .iter()
                .map(|m| {
                    m.get(f.offset..)
                        .and_then(|b| f.kind.read(b))
                        .unwrap_or(f64::NAN)
                })
                .collect(),
        )
    }
}

/// A ULog file, read.
#[derive(Debug, Clone)]
pub struct Ulog {
    /// The file.
    pub path: PathBuf,
    /// The header's timestamp, µs since boot (the log's start).
    pub start_us: u64,
    /// Information messages (`I`) whose value is a string or a number, as text.
    pub info: BTreeMap<String, String>,
    /// Every subscription, in the order of the file.
    pub topics: Vec<UlogTopic>,
    /// Byte offset of a last message the file's end cuts (a log whose writing stopped midway):
    /// the messages before it are read, and what followed it is missing.
    pub cut_at: Option<usize>,
}

impl Ulog {
    /// The subscriptions of `name`, in instance order.
    pub fn topic(&self, name: &str) -> Vec<&UlogTopic> {
        let mut t: Vec<&UlogTopic> = self.topics.iter().filter(|t| t.name == name).collect();
        t.sort_by_key(|t| t.instance);
        t
    }
}

/// Flattens format `name` into scalar fields starting at `base`; returns its size.
fn flatten(
    formats: &BTreeMap<String, String>,
    name: &str,
    prefix: &str,
    base: usize,
    out: &mut Vec<Field>,
    depth: usize,
) -> Result<usize, String> {
    if depth > 16 {
        return Err(format!("format `{name}` nests too deep"));
    }
    let text = formats
        .get(name)
        .ok_or_else(|| format!("no format definition `{name}`"))?;
    let mut offset = base;
    for decl in text.split(';').filter(|d| !d.is_empty()) {
        let (ty, field) = decl
            .split_once(' ')
            .ok_or_else(|| format!("format `{name}`: field `{decl}` has no type"))?;
        let (ty, count) = match ty.split_once('[') {
            Some((t, n)) => {
                let n: usize = n
                    .trim_end_matches(']')
                    .parse()
                    .map_err(|_| format!("format `{name}`: bad array size in `{decl}`"))?;
                (t, Some(n))
            }
            None => (ty, None),
        };
        for k in 0..count.unwrap_or(1) {
            let full = match count {
                Some(_) => format!("{prefix}{field}[{k}]"),
                None => format!("{prefix}{field}"),
            };
            match Scalar::parse(ty) {
                Some(kind) => {
                    if !field.starts_with("_padding") {
                        out.push(Field {
                            name: full,
                            kind,
                            offset,
                        });
                    }
                    offset += kind.size();
                }
                None => {
                    let size = flatten(formats, ty, &format!("{full}."), offset, out, depth + 1)?;
                    offset = size;
                }
            }
        }
    }
    Ok(offset)
}

/// Reads a ULog file.
pub fn read_ulog(path: &Path) -> Result<Ulog, UlogError> {
    let bytes = std::fs::read(path).map_err(|source| UlogError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    read_ulog_bytes(path, &bytes)
}

/// What is wrong with the 16-byte file header (magic, version, timestamp), if anything: a file
/// that starts like ULog but breaks the magic, or ends inside the header, is a damaged ULog file;
/// anything else is not ULog at all.
fn header_fault(bytes: &[u8]) -> Option<String> {
    if bytes.len() >= 16 && bytes[..7] == MAGIC {
        return None;
    }
    let shared = bytes.iter().zip(MAGIC).filter(|(a, b)| **a == *b).count();
    Some(
        if bytes.len() < 16 && MAGIC.starts_with(&bytes[..bytes.len().min(7)]) {
            format!(
            "the file ends inside the 16-byte ULog header ({} bytes): the file is corrupt (truncated)",
            bytes.len()
        )
        } else if shared >= 4 {
            format!(
            "the ULog header is corrupt: its magic reads {}, not `ULog` 01 12 35: the file is corrupt",
            bytes
                .iter()
                .take(7)
                .map(|b| format!("{b:02x}"))
                .collect::<Vec<_>>()
                .join(" ")
        )
        } else {
            "not a ULog file (magic `ULog` 01 12 35 missing)".into()
        },
    )
}

/// Reads ULog bytes held in memory; `path` names them in errors.
pub fn read_ulog_bytes(path: &Path, bytes: &[u8]) -> Result<Ulog, UlogError> {
    // Past a valid header every malformed message is damage to the file, and is named so.
    let bad = |offset: usize, reason: String| UlogError::Format {
        path: path.to_path_buf(),
        offset,
        reason: format!("{reason}: the file is corrupt"),
    };
    if let Some(reason) = header_fault(bytes) {
        return Err(UlogError::Format {
            path: path.to_path_buf(),
            offset: 0,
            reason,
        });
    }
    let start_us = u64::from_le_bytes(bytes[8..16].try_into().unwrap_or_default());
    let mut formats: BTreeMap<String, String> = BTreeMap::new();
    let mut info = BTreeMap::new();
    let mut topics: Vec<UlogTopic> = Vec::new();
    let mut by_id: BTreeMap<u16, usize> = BTreeMap::new();
    let mut appended: Vec<usize> = Vec::new();
    let mut pos = 16usize;
    let mut cut_at = None;
    while pos + 3 <= bytes.len() {
        if let Some(&next) = appended.first() {
            if pos >= next || pos + 3 > next {
                pos = next;
                appended.remove(0);
                continue;
            }
        }
        let size = usize::from(u16::from_le_bytes([bytes[pos], bytes[pos + 1]]));
        let kind = bytes[pos + 2];
        let start = pos + 3;
        let end = start + size;
        if let Some(&next) = appended.first() {
            if end > next {
                // A message cut by the log's end: the appended data continues at `next`.
                pos = next;
                appended.remove(0);
                continue;
            }
        }
        if end > bytes.len() {
            // The last message was cut when the log ended: what came before is complete.
            cut_at = Some(pos);
            break;
        }
        let body = &bytes[start..end];
        let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
        match kind {
            b'B' if body.len() >= 40 => {
                for k in 0..3 {
                    let at = 16 + 8 * k;
                    let offset =
                        u64::from_le_bytes(body[at..at + 8].try_into().unwrap_or_default());
                    if offset > 0 {
                        appended.push(usize::try_from(offset).unwrap_or(usize::MAX));
                    }
                }
                appended.sort_unstable();
                if body[8] & !1 != 0 {
                    return Err(UlogError::Format {
                        path: path.to_path_buf(),
                        offset: pos,
                        reason: format!(
                            "incompatible flags {:#04x} (this reader knows bit 0, appended data): the file is corrupt, or from a newer ULog version",
                            body[8]
                        ),
                    });
                }
            }
            b'F' => {
                let definition = text(body);
                let (name, fields) = definition.split_once(':').ok_or_else(|| {
                    bad(pos, format!("format definition `{definition}` has no `:`"))
                })?;
                formats.insert(name.to_owned(), fields.to_owned());
            }
            b'I' => {
                let key_len = usize::from(*body.first().unwrap_or(&0));
                let key = body.get(1..1 + key_len).map(text).unwrap_or_default();
                let value = body.get(1 + key_len..).unwrap_or_default();
                if let Some((ty, name)) = key.split_once(' ') {
                    let shown = if ty.starts_with("char[") {
                        text(value).trim_end_matches('\0').to_owned()
                    } else if let Some(s) = Scalar::parse(ty) {
                        s.read(value).map(|v| v.to_string()).unwrap_or_default()
                    } else {
                        format!("{} bytes", value.len())
                    };
                    info.insert(name.to_owned(), shown);
                }
            }
            b'A' => {
                if body.len() < 3 {
                    return Err(bad(pos, "subscription message shorter than 3 bytes".into()));
                }
                let instance = body[0];
                let id = u16::from_le_bytes([body[1], body[2]]);
                let name = text(&body[3..]).trim_end_matches('\0').to_owned();
                let mut fields = Vec::new();
                flatten(&formats, &name, "", 0, &mut fields, 0)
                    .map_err(|reason| bad(pos, reason))?;
                // PX4 does not log a format's trailing padding: a message ends with its last
                // field.
                let size = fields
                    .iter()
                    .map(|f| f.offset + f.kind.size())
                    .max()
                    .unwrap_or(0);
                by_id.insert(id, topics.len());
                topics.push(UlogTopic {
                    name,
                    instance,
                    fields,
                    size,
                    messages: Vec::new(),
                });
            }
            b'D' => {
                if body.len() < 2 {
                    return Err(bad(pos, "data message shorter than 2 bytes".into()));
                }
                let id = u16::from_le_bytes([body[0], body[1]]);
                let topic = by_id
                    .get(&id)
                    .and_then(|&i| topics.get_mut(i))
                    .ok_or_else(|| {
                        bad(
                            pos,
                            format!("data for msg_id {id}, which no subscription defines"),
                        )
                    })?;
                let data = &body[2..];
                if data.len() < topic.size {
                    return Err(bad(
                        pos,
                        format!(
                            "`{}` instance {}: {} data bytes, its format needs {}",
                            topic.name,
                            topic.instance,
                            data.len(),
                            topic.size
                        ),
                    ));
                }
                topic.messages.push(data.to_vec());
            }
            _ => {}
        }
        pos = end;
    }
    if cut_at.is_none() && pos < bytes.len() && appended.is_empty() {
        // Fewer than a message header's 3 bytes left: cut as well.
        cut_at = Some(pos);
    }
    Ok(Ulog {
        path: path.to_path_buf(),
        start_us,
        info,
        topics,
        cut_at,
    })
}
