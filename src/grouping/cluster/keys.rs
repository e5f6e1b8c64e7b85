//! Per-body keys: seeded tie tags and Morton codes' bit spreading.

/// splitmix64: the seeded tie tag of a body id.
pub(in crate::grouping) fn tie_tag(seed: Option<u64>, id: u32) -> u64 {
    match seed {
        None => id as u64,
        Some(s) => {
            let mut z = s ^ (id as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }
    }
}

/// Spreads the low 21 bits of `v` to every third bit.
pub(in crate::grouping) fn spread_bits(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}
