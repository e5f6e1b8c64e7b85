//! The `.rrd`'s part lines (`log/doublings`): one per part of the run, except the partitioned
//! schedule's smallest chunks. A 10^6-triangle run has ~600,000 chunks of 3 or 4 bodies; a line
//! each made the log 600,000 lines long (nothing a reader scrolls through) and cost time and
//! space for nothing. Each run of consecutive small chunks becomes one line at the
//! merge where the run starts; the `.mcap` still has every part on `/grouping/part`.

use crate::grouping::{Part, PartKind};

/// Chunks of at most this many bodies are summarised, not logged one by one.
pub(super) const SMALL_CHUNK: u32 = 8;

/// Consecutive small chunks not yet logged.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Run {
    first: u32,
    last: u32,
    first_step: u32,
    bodies: u64,
    keep: u64,
}

/// Turns part events into log lines; see the [module docs](self).
#[derive(Debug, Default)]
pub(super) struct PartLines {
    run: Option<Run>,
}

impl PartLines {
    /// Logs part `p` through `line(merge tick, text)`: a small chunk joins the current run; any
    /// other part first ends the run, then gets its own line (at the current merge, `merge`).
    pub(super) fn part(&mut self, p: &Part, merge: u32, mut line: impl FnMut(u32, &str)) {
        if let PartKind::Chunk { keep, .. } = p.kind
            && p.bodies <= SMALL_CHUNK
        {
            let run = self.run.get_or_insert(Run {
                first: p.id,
                last: p.id,
                first_step: p.first_step,
                bodies: 0,
                keep: 0,
            });
            run.last = p.id;
            run.bodies += u64::from(p.bodies);
            run.keep += u64::from(keep);
            return;
        }
        self.end(&mut line);
        line(merge, &p.to_string());
    }

    /// Logs the current run of small chunks, if any, as one line at the merge where it starts.
    pub(super) fn end(&mut self, mut line: impl FnMut(u32, &str)) {
        if let Some(r) = self.run.take() {
            let count = r.last - r.first + 1;
            let text = if count == 1 {
                format!(
                    "part {}: a chunk of at most {SMALL_CHUNK} bodies ({} → {}) from merge {}",
                    r.first, r.bodies, r.keep, r.first_step
                )
            } else {
                format!(
                    "parts {}–{}: {count} chunks of at most {SMALL_CHUNK} bodies ({} → {}) from \
                     merge {} (one by one in the .mcap's /grouping/part)",
                    r.first, r.last, r.bodies, r.keep, r.first_step
                )
            };
            line(r.first_step, &text);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chunk(id: u32, bodies: u32, keep: u32, first_step: u32) -> Part {
        Part {
            id,
            kind: PartKind::Chunk { level: 3, keep },
            bodies,
            first_step,
        }
    }

    #[test]
    fn runs_of_small_chunks_become_one_line_each() {
        let mut log = PartLines::default();
        let mut lines: Vec<(u32, String)> = Vec::new();
        let mut push = |m: u32, t: &str| lines.push((m, t.to_string()));
        log.part(&chunk(0, 4, 2, 0), 0, &mut push);
        log.part(&chunk(1, 3, 2, 2), 2, &mut push);
        log.part(&chunk(2, 20, 5, 3), 3, &mut push);
        log.part(&chunk(3, 4, 2, 18), 18, &mut push);
        let top = Part {
            id: 4,
            kind: PartKind::Top,
            bodies: 3,
            first_step: 20,
        };
        log.part(&top, 20, &mut push);
        log.end(&mut push);
        assert_eq!(
            lines,
            [
                (
                    0,
                    "parts 0–1: 2 chunks of at most 8 bodies (7 → 4) from merge 0 (one by one \
                     in the .mcap's /grouping/part)"
                        .to_string()
                ),
                (3, chunk(2, 20, 5, 3).to_string()),
                (
                    18,
                    "part 3: a chunk of at most 8 bodies (4 → 2) from merge 18".to_string()
                ),
                (20, top.to_string()),
            ]
        );
    }

    #[test]
    fn a_run_still_open_at_the_end_is_logged_by_end() {
        let mut log = PartLines::default();
        let mut lines = Vec::new();
        log.part(&chunk(0, 2, 1, 0), 0, |m, t| lines.push((m, t.to_string())));
        assert!(lines.is_empty());
        log.end(|m, t| lines.push((m, t.to_string())));
        log.end(|m, t| lines.push((m, t.to_string())));
        assert_eq!(lines.len(), 1);
        assert_eq!(lines[0].0, 0);
    }
}
