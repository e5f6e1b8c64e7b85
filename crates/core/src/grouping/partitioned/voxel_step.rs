//! Subproblems of more than `brute_force::MAX_BODIES` bodies: the exact schedule's voxel
//! hash and MPairs on the subproblem's bodies, stopped at `keep` bodies.

use super::subproblem::{Body, Counters, MergeInfo, MergeSlots, RunInputs};
use crate::events::{Event, Observer};
use crate::grouping::Budget;
use crate::grouping::cluster::run_boxes_until;
use std::sync::atomic::Ordering;

/// Collects the merges of a voxel-hash subproblem for the events.
struct MergeLog(Vec<MergeInfo>);

impl Observer for MergeLog {
    fn on_event(&mut self, event: &Event<'_>) {
        if let Event::Merge(m) = event {
            self.0.push(MergeInfo {
                round: m.round,
                fill: m.fill,
                balance: m.balance,
                cost: m.cost,
                queue_len: m.queue_len,
                active: m.active,
            });
        }
    }
}

/// A subproblem of more than `brute_force::MAX_BODIES` bodies, with the exact schedule's voxel hash and
/// MPairs (local ids mapped increasingly onto the run's ids, ties broken by the run's ids).
pub(super) fn combine_by_voxels(
    ctx: &RunInputs,
    mut bodies: Vec<Body>,
    keep: usize,
    out: &mut MergeSlots<'_>,
) -> Option<Vec<Body>> {
    let m = bodies.len();
    if m <= keep {
        return Some(bodies);
    }
    bodies.sort_unstable_by_key(|b| b.id);
    let first_new = out.first_new;
    let id = |l: u32| {
        if (l as usize) < m {
            bodies[l as usize].id
        } else {
            first_new + (l - m as u32)
        }
    };
    let used = ctx.pairs.load(Ordering::Relaxed);
    let budget = Budget {
        stop: ctx.budget.stop,
        deadline: ctx.budget.deadline,
        max_pairs: ctx.budget.max_pairs.map(|p| p.saturating_sub(used)),
    };
    let boxes = bodies.iter().map(|b| b.aabb).collect();
    let mut log = MergeLog(Vec::new());
    let part = if out.listens() {
        log.0.reserve(m - keep);
        run_boxes_until(boxes, keep, id, &ctx.params, &mut log, &budget)
    } else {
        run_boxes_until(boxes, keep, id, &ctx.params, (), &budget)
    };
    let part = match part {
        Ok(p) => p,
        Err(s) => {
            ctx.stop(s.reason);
            return None;
        }
    };
    for (s, ch) in part.children.iter().enumerate() {
        let info = log.0.get(s).copied().unwrap_or_default();
        out.put(s, ch.map(id), part.aabb[s], part.diameter[s], info);
    }
    let st = &part.stats;
    out.stats.add(&Counters {
        eligible_pairs: st.eligible_pairs,
        candidates: st.candidates,
        pops: st.pops,
        stale_pops: st.stale_pops,
        peak_queue: st.peak_queue,
        rounds: part.rounds,
    });
    Some(
        part.roots
            .iter()
            .map(|&l| Body {
                id: id(l),
                first_round: if (l as usize) < m {
                    bodies[l as usize].first_round
                } else {
                    ctx.dl.first(part.diameter[l as usize - m])
                },
                aabb: if (l as usize) < m {
                    bodies[l as usize].aabb
                } else {
                    part.aabb[l as usize - m]
                },
                diameter: if (l as usize) < m {
                    bodies[l as usize].diameter
                } else {
                    part.diameter[l as usize - m]
                },
            })
            .collect(),
    )
}
