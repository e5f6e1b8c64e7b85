//! Morton (Z-order) codes: 21 bits per axis interleaved into 63.

/// Spreads the low 21 bits of `v` to every third bit (one axis of a 63-bit Morton code).
#[inline]
pub fn spread_bits(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spreading_interleaves_the_bits() {
        assert_eq!(spread_bits(0b111), 0b1001001);
        assert_eq!(spread_bits(1 << 20), 1 << 60);
        assert_eq!(spread_bits(u64::MAX), 0x1249_2492_4924_9249);
    }
}
