//! The protobuf wire parsing behind the flat messages' decoders.

/// A scalar the flat decoder understands: its protobuf wire type and conversion from the raw
/// varint or 64-bit value.
pub trait WireScalar: Sized {
    /// Protobuf wire type: 0 (varint) or 1 (64-bit).
    const WIRE: u8;
    /// Whether the field may be absent (proto3 `optional`, a Rust `Option`).
    const OPTIONAL: bool = false;
    /// Converts the raw field value.
    fn from_raw(raw: u64) -> Option<Self>;
}

/// An optional field: written only when `Some` (explicit presence), `None` when absent.
impl<T: WireScalar> WireScalar for Option<T> {
    const WIRE: u8 = T::WIRE;
    const OPTIONAL: bool = true;
    fn from_raw(raw: u64) -> Option<Self> {
        T::from_raw(raw).map(Some)
    }
}

impl WireScalar for u32 {
    const WIRE: u8 = 0;
    fn from_raw(raw: u64) -> Option<Self> {
        u32::try_from(raw).ok()
    }
}

impl WireScalar for u64 {
    const WIRE: u8 = 0;
    fn from_raw(raw: u64) -> Option<Self> {
        Some(raw)
    }
}

impl WireScalar for bool {
    const WIRE: u8 = 0;
    fn from_raw(raw: u64) -> Option<Self> {
        Some(raw != 0)
    }
}

impl WireScalar for f64 {
    const WIRE: u8 = 1;
    fn from_raw(raw: u64) -> Option<Self> {
        Some(f64::from_bits(raw))
    }
}

/// Reads one varint at `*pos`.
fn varint(buf: &[u8], pos: &mut usize) -> Result<u64, String> {
    let mut v = 0u64;
    for shift in (0..64).step_by(7) {
        let byte = *buf.get(*pos).ok_or("message ends inside a varint")?;
        *pos += 1;
        v |= u64::from(byte & 0x7f) << shift;
        if byte & 0x80 == 0 {
            return Ok(v);
        }
    }
    Err("varint longer than 10 bytes".into())
}

/// Splits a protobuf message into `(field number, wire type, raw value)` for its varint and
/// 64-bit fields; length-delimited and 32-bit fields are skipped.
pub fn wire_fields(buf: &[u8]) -> Result<Vec<(u64, u8, u64)>, String> {
    let mut out = Vec::new();
    let mut pos = 0;
    while pos < buf.len() {
        let tag = varint(buf, &mut pos)?;
        let (field, wire) = (tag >> 3, (tag & 7) as u8);
        match wire {
            0 => out.push((field, 0, varint(buf, &mut pos)?)),
            1 => {
                let bytes = buf
                    .get(pos..pos + 8)
                    .ok_or("message ends inside a double")?;
                out.push((
                    field,
                    1,
                    u64::from_le_bytes(bytes.try_into().expect("8 bytes")),
                ));
                pos += 8;
            }
            2 => {
                let len = varint(buf, &mut pos)?;
                pos = usize::try_from(len)
                    .ok()
                    .and_then(|l| pos.checked_add(l))
                    .filter(|&end| end <= buf.len())
                    .ok_or("length-delimited field runs past the message")?;
            }
            5 => {
                pos = pos
                    .checked_add(4)
                    .filter(|&e| e <= buf.len())
                    .ok_or("message ends inside a fixed32")?
            }
            w => return Err(format!("unsupported wire type {w}")),
        }
    }
    Ok(out)
}
