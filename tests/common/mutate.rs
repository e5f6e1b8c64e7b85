//! Byte-level helpers of the fuzz tests' mutations.

/// The index at fraction `f` of `len` (clamped to `len`).
pub fn at(f: f64, len: usize) -> usize {
    ((f * len as f64) as usize).min(len)
}

/// Byte ranges of the maximal runs of bytes for which `num` holds (a format's number tokens).
pub fn number_tokens(text: &[u8], num: impl Fn(u8) -> bool) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < text.len() {
        if num(text[i]) && (i == 0 || !num(text[i - 1])) {
            let start = i;
            while i < text.len() && num(text[i]) {
                i += 1;
            }
            out.push((start, i));
        } else {
            i += 1;
        }
    }
    out
}

/// Byte ranges of the lines of `text`, each with its newline.
pub fn lines(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &b) in text.iter().enumerate() {
        if b == b'\n' {
            out.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < text.len() {
        out.push((start, text.len()));
    }
    out
}

/// Deletes (`delete`) or duplicates the line at index `k` (modulo the line count) of `text`;
/// nothing when it has no line.
pub fn delete_or_duplicate_line(text: &mut Vec<u8>, k: usize, delete: bool) {
    let ls = lines(text);
    if ls.is_empty() {
        return;
    }
    let (a, b) = ls[k % ls.len()];
    if delete {
        text.drain(a..b);
    } else {
        let copy = text[a..b].to_vec();
        text.splice(b..b, copy);
    }
}
