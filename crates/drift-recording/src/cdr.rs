//! Minimal little-endian CDR (the ROS 2 wire format) for our flat message types.
//!
//! Layout rules used here (OMG CDR, XCDR1): a 4-byte encapsulation header `00 01 00 00`
//! (CDR little endian), then fields in order, each primitive aligned to its own size
//! relative to the first byte after the header; a sequence is a `uint32` count followed by
//! its elements; a string is a `uint32` length including the terminating NUL, the bytes,
//! and the NUL.

/// CDR little-endian encapsulation header.
pub const HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Appends CDR fields to a reusable buffer.
#[derive(Debug, Default)]
pub struct Encoder {
    buf: Vec<u8>,
}

impl Encoder {
    /// Starts a new message (clears the buffer, keeps its capacity).
    pub fn begin(&mut self) -> &mut Self {
        self.buf.clear();
        self.buf.extend_from_slice(&HEADER);
        self
    }
    fn align(&mut self, n: usize) {
        while (self.buf.len() - HEADER.len()) % n != 0 {
            self.buf.push(0);
        }
    }
    /// A `bool` (one byte).
    pub fn bool(&mut self, v: bool) -> &mut Self {
        self.buf.push(u8::from(v));
        self
    }
    /// A `uint32`.
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }
    /// An `int32`.
    pub fn i32(&mut self, v: i32) -> &mut Self {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }
    /// A `float64`.
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }
    /// A `string`.
    pub fn string(&mut self, s: &str) -> &mut Self {
        self.u32(s.len() as u32 + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
        self
    }
    /// A `float32[]`.
    pub fn f32s(&mut self, v: &[f32]) -> &mut Self {
        self.u32(v.len() as u32);
        self.buf.reserve(v.len() * 4);
        for x in v {
            self.buf.extend_from_slice(&x.to_le_bytes());
        }
        self
    }
    /// An `int16[]`.
    pub fn i16s(&mut self, v: &[i16]) -> &mut Self {
        self.u32(v.len() as u32);
        self.buf.reserve(v.len() * 2);
        for x in v {
            self.buf.extend_from_slice(&x.to_le_bytes());
        }
        self
    }
    /// The encoded message.
    pub fn bytes(&self) -> &[u8] {
        &self.buf
    }
}

/// Reads CDR fields in order; every read checks bounds.
#[derive(Debug)]
pub struct Decoder<'a> {
    data: &'a [u8],
    pos: usize,
}

/// Why a message could not be decoded.
pub type DecodeError = String;

impl<'a> Decoder<'a> {
    /// Checks the encapsulation header.
    pub fn new(data: &'a [u8]) -> Result<Self, DecodeError> {
        if data.len() < 4 || data[..4] != HEADER {
            return Err("not CDR little-endian (bad encapsulation header)".into());
        }
        Ok(Self { data, pos: 4 })
    }
    /// Checks the encapsulation header of a message written by ROS 2: CDR little endian with any
    /// options bytes (a DDS implementation may note its trailing padding there); big-endian CDR is
    /// refused by name.
    pub fn new_ros2(data: &'a [u8]) -> Result<Self, DecodeError> {
        match data.get(..2) {
            Some([0x00, 0x01]) if data.len() >= 4 => Ok(Self { data, pos: 4 }),
            Some([0x00, 0x00]) => Err("big-endian CDR (encapsulation 00 00): only little-endian CDR is read; re-record on a little-endian machine or convert the bag".into()),
            Some([a, b]) => Err(format!(
                "encapsulation {a:02x} {b:02x} is not plain CDR (expected 00 01, little-endian XCDR1)"
            )),
            _ => Err(format!("message of {} bytes has no CDR encapsulation header", data.len())),
        }
    }
    fn align(&mut self, n: usize) {
        while (self.pos - HEADER.len()) % n != 0 {
            self.pos += 1;
        }
    }
    fn take(&mut self, n: usize) -> Result<&'a [u8], DecodeError> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.data.len())
            .ok_or_else(|| {
                format!(
                    "message truncated: need {n} bytes at offset {}, have {}",
                    self.pos,
                    self.data.len()
                )
            })?;
        let s = &self.data[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    /// A `bool`.
    pub fn bool(&mut self) -> Result<bool, DecodeError> {
        Ok(self.take(1)?[0] != 0)
    }
    /// A `uint32`.
    pub fn u32(&mut self) -> Result<u32, DecodeError> {
        self.align(4);
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    /// An `int32`.
    pub fn i32(&mut self) -> Result<i32, DecodeError> {
        self.align(4);
        let b = self.take(4)?;
        Ok(i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    /// A `float64`.
    pub fn f64(&mut self) -> Result<f64, DecodeError> {
        self.align(8);
        let b = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(f64::from_le_bytes(a))
    }
    /// A `string`.
    pub fn string(&mut self) -> Result<String, DecodeError> {
        let n = self.u32()? as usize;
        let b = self.take(n)?;
        let text = b
            .strip_suffix(&[0])
            .ok_or("string without terminating NUL")?;
        String::from_utf8(text.to_vec()).map_err(|e| format!("string is not UTF-8: {e}"))
    }
    /// Appends a `float32[]` to `out`; returns its length.
    pub fn f32s_into(&mut self, out: &mut Vec<f32>) -> Result<usize, DecodeError> {
        let n = self.u32()? as usize;
        let b = self.take(n.checked_mul(4).ok_or("sequence too long")?)?;
        out.extend(
            b.chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])),
        );
        Ok(n)
    }
    /// Appends an `int16[]` to `out`; returns its length.
    pub fn i16s_into(&mut self, out: &mut Vec<i16>) -> Result<usize, DecodeError> {
        let n = self.u32()? as usize;
        let b = self.take(n.checked_mul(2).ok_or("sequence too long")?)?;
        out.extend(b.chunks_exact(2).map(|c| i16::from_le_bytes([c[0], c[1]])));
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_with_alignment() {
        let mut e = Encoder::default();
        e.begin()
            .bool(true)
            .string("protocol")
            .u32(7)
            .f64(1.5)
            .i16s(&[1, -2, 3])
            .f32s(&[0.25, -1.0]);
        let mut d = Decoder::new(e.bytes()).unwrap();
        assert!(d.bool().unwrap());
        assert_eq!(d.string().unwrap(), "protocol");
        assert_eq!(d.u32().unwrap(), 7);
        assert_eq!(d.f64().unwrap(), 1.5);
        let mut i = Vec::new();
        d.i16s_into(&mut i).unwrap();
        assert_eq!(i, [1, -2, 3]);
        let mut f = Vec::new();
        d.f32s_into(&mut f).unwrap();
        assert_eq!(f, [0.25, -1.0]);
        // The f64 after a 1-byte bool + 13-byte string + u32 must sit on an 8-byte boundary.
        assert!(Decoder::new(&e.bytes()[..10]).unwrap().bool().is_ok());
        assert!(Decoder::new(&[0, 0, 0, 0]).is_err());
    }
}
