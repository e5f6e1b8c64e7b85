//! Per-body keys: seeded tie tags.

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
