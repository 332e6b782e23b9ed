//! The CDR byte layout: little-endian primitives aligned to their size, counted from the byte
//! after the 4-byte encapsulation header; strings and sequences prefixed by a `u32` length.

/// Encapsulation header of little-endian plain CDR.
pub const CDR_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Why bytes could not be decoded.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CdrError {
    #[error("message ends at byte {at}, {needed} more bytes needed")]
    Truncated { at: usize, needed: usize },
    #[error("unsupported encapsulation header {0:02x?} (only little-endian CDR)")]
    Encapsulation([u8; 4]),
    #[error("byte {at}: {what}")]
    Invalid { at: usize, what: String },
}

/// Appends CDR to a reusable buffer.
#[derive(Debug, Default)]
pub struct CdrWriter {
    buf: Vec<u8>,
    /// The `frame_id` a message's headers carry: its type's [`Cdr::FRAME_ID`].
    frame_id: &'static str,
}

impl CdrWriter {
    /// Starts a message in `buf` (cleared), writing the encapsulation header.
    pub fn start(mut buf: Vec<u8>) -> Self {
        buf.clear();
        buf.extend_from_slice(&CDR_LE);
        Self { buf, frame_id: "" }
    }

    /// The frame the message being written is expressed in (`""` for a type without one).
    pub fn frame_id(&self) -> &'static str {
        self.frame_id
    }

    pub fn finish(self) -> Vec<u8> {
        self.buf
    }

    fn align(&mut self, n: usize) {
        let pos = self.buf.len() - CDR_LE.len();
        self.buf.resize(self.buf.len() + (n - pos % n) % n, 0);
    }

    pub fn bytes(&mut self, b: &[u8]) {
        self.buf.extend_from_slice(b);
    }

    pub fn string(&mut self, s: &str) {
        self.prim((s.len() + 1) as u32);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// A `uint8[]` sequence.
    pub fn byte_seq(&mut self, b: &[u8]) {
        self.prim(b.len() as u32);
        self.buf.extend_from_slice(b);
    }

    pub fn prim<P: Primitive>(&mut self, v: P) {
        self.align(P::SIZE);
        v.put(&mut self.buf);
    }
}

/// Reads CDR from a message's bytes.
#[derive(Debug)]
pub struct CdrReader<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> CdrReader<'a> {
    pub fn new(data: &'a [u8]) -> Result<Self, CdrError> {
        let head: [u8; 4] =
            data.get(..4).and_then(|h| h.try_into().ok()).ok_or(CdrError::Truncated { at: 0, needed: 4 })?;
        if head != CDR_LE {
            return Err(CdrError::Encapsulation(head));
        }
        Ok(Self { data, pos: 4 })
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], CdrError> {
        let end = self.pos.saturating_add(n);
        // The shortfall is worked out only when there is one (eagerly, it underflowed in debug
        // builds on every read that succeeded).
        let s = self.data.get(self.pos..end).ok_or_else(|| CdrError::Truncated {
            at: self.pos,
            needed: end.saturating_sub(self.data.len()),
        })?;
        self.pos = end;
        Ok(s)
    }

    pub fn prim<P: Primitive>(&mut self) -> Result<P, CdrError> {
        let rel = self.pos - 4;
        self.take((P::SIZE - rel % P::SIZE) % P::SIZE)?;
        Ok(P::get(self.take(P::SIZE)?))
    }

    pub fn string(&mut self) -> Result<String, CdrError> {
        let at = self.pos;
        let n = self.prim::<u32>()? as usize;
        let raw = self.take(n)?;
        let text =
            raw.strip_suffix(&[0]).ok_or(CdrError::Invalid { at, what: "string lacks its NUL".into() })?;
        String::from_utf8(text.to_vec())
            .map_err(|_| CdrError::Invalid { at, what: "string is not UTF-8".into() })
    }

    pub fn byte_seq(&mut self) -> Result<&'a [u8], CdrError> {
        let n = self.prim::<u32>()? as usize;
        self.take(n)
    }

    /// Where the next read starts, from the message's first byte.
    pub fn offset(&self) -> usize {
        self.pos
    }

    /// Bytes left unread.
    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }
}

/// A fixed-size little-endian number.
pub trait Primitive: Copy {
    const SIZE: usize;
    fn put(self, buf: &mut Vec<u8>);
    fn get(b: &[u8]) -> Self;
}

macro_rules! primitive {
    ($($t:ty),*) => {$(
        impl Primitive for $t {
            const SIZE: usize = core::mem::size_of::<$t>();
            fn put(self, buf: &mut Vec<u8>) {
                buf.extend_from_slice(&self.to_le_bytes());
            }
            fn get(b: &[u8]) -> Self {
                let mut a = [0u8; core::mem::size_of::<$t>()];
                a.copy_from_slice(b);
                <$t>::from_le_bytes(a)
            }
        }
        impl Cdr for $t {
            fn write(&self, w: &mut CdrWriter) {
                w.prim(*self);
            }
            fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
                r.prim()
            }
        }
    )*};
}
primitive!(u8, i8, u16, i16, i32, u32, u64, i64, f32, f64);

/// A value with a CDR form.
pub trait Cdr: Sized {
    /// The coordinate frame (`frames.rs`) the headers of a message of this type name.
    const FRAME_ID: &'static str = "";
    fn write(&self, w: &mut CdrWriter);
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError>;
}

impl<T: Cdr + Copy + Default, const N: usize> Cdr for [T; N] {
    fn write(&self, w: &mut CdrWriter) {
        self.iter().for_each(|v| v.write(w));
    }
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let mut out = [T::default(); N];
        for v in &mut out {
            *v = T::read(r)?;
        }
        Ok(out)
    }
}

/// Encodes `v` as a complete CDR message into `buf` (reused).
pub fn encode<T: Cdr>(v: &T, buf: Vec<u8>) -> Vec<u8> {
    let mut w = CdrWriter::start(buf);
    w.frame_id = T::FRAME_ID;
    v.write(&mut w);
    w.finish()
}

/// Decodes a complete CDR message; trailing bytes beyond alignment padding are an error.
pub fn decode<T: Cdr>(data: &[u8]) -> Result<T, CdrError> {
    let mut r = CdrReader::new(data)?;
    let v = T::read(&mut r)?;
    if r.remaining() >= 8 {
        return Err(CdrError::Invalid {
            at: data.len() - r.remaining(),
            what: format!("{} unexpected trailing bytes", r.remaining()),
        });
    }
    Ok(v)
}
