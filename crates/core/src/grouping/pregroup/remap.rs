//! Events of a part run with local ids, buffered while parts run in parallel and passed on
//! with global ids in the documented order.

use crate::events::{Event, Merge, Observer, OwnedEvent};

/// An owned copy of the events of one part run (no `Part`, no `Finish`).
#[derive(Default)]
pub(super) struct Buffer(pub Vec<OwnedEvent>);

impl Observer for Buffer {
    fn on_event(&mut self, event: &Event<'_>) {
        match event {
            // A part's own parts, finish and refinement (never inside a grouping) are not replayed.
            Event::Part(_)
            | Event::Finish { .. }
            | Event::RefineStart { .. }
            | Event::Refine(_) => {}
            e => self.0.push(OwnedEvent::of(e)),
        }
    }
}

impl Buffer {
    /// Passes the buffered events on to `to`.
    pub(super) fn replay<O: Observer>(&self, to: &mut O) {
        for e in &self.0 {
            to.on_event(&e.event());
        }
    }

    /// The buffered merges, in order.
    pub(super) fn merges(&self) -> impl Iterator<Item = Merge> + '_ {
        self.0.iter().filter_map(|e| match e.event() {
            Event::Merge(m) => Some(m),
            _ => None,
        })
    }
}

/// Local ids of a part → global ids of the whole run.
#[derive(Clone, Copy)]
pub(super) struct IdMap<'a> {
    /// Global id of each local leaf, increasing.
    pub leaves: &'a [u32],
    /// Global id of the part's first interior node.
    pub base: u32,
    /// Number of leaves of the whole run (global step = global id − n).
    pub n: u32,
    /// Rounds run before this part (global round = local round + `round0`).
    pub round0: u32,
}

impl IdMap<'_> {
    /// The global id of local body `x`. Increasing in `x`, so merge events keep `a < b < new`.
    #[inline]
    pub(super) fn get(&self, x: u32) -> u32 {
        let k = self.leaves.len() as u32;
        if x < k {
            self.leaves[x as usize]
        } else {
            self.base + (x - k)
        }
    }
}

/// Forwards a part run's events to `inner` with global ids and rounds (rounds are counted over
/// the whole run, so the round timeline of a recording only moves forward); `Part` and
/// `Finish` are dropped (the caller announces parts and the one finish).
pub(super) struct Remap<'a, O> {
    pub inner: &'a mut O,
    pub map: IdMap<'a>,
    scratch: Vec<u32>,
}

impl<'a, O: Observer> Remap<'a, O> {
    pub(super) fn new(inner: &'a mut O, map: IdMap<'a>) -> Self {
        Remap {
            inner,
            map,
            scratch: Vec::new(),
        }
    }
}

impl<O: Observer> Observer for Remap<'_, O> {
    fn on_event(&mut self, event: &Event<'_>) {
        let m = self.map;
        match *event {
            Event::RoundStart {
                round,
                dlimit,
                glimit,
                active,
                dormant,
                pairs,
            } => {
                self.scratch.clear();
                self.scratch.extend(active.iter().map(|&x| m.get(x)));
                self.inner.on_event(&Event::RoundStart {
                    round: round + m.round0,
                    dlimit,
                    glimit,
                    active: &self.scratch,
                    dormant,
                    pairs,
                });
            }
            Event::Merge(x) => {
                let new = m.get(x.new);
                self.inner.on_event(&Event::Merge(Merge {
                    step: new - m.n,
                    round: x.round + m.round0,
                    a: m.get(x.a),
                    b: m.get(x.b),
                    new,
                    ..x
                }));
            }
            Event::Dormant {
                round,
                body,
                diameter,
            } => self.inner.on_event(&Event::Dormant {
                round: round + m.round0,
                body: m.get(body),
                diameter,
            }),
            Event::Doubling {
                round,
                merges,
                dlimit,
                glimit,
            } => self.inner.on_event(&Event::Doubling {
                round: round + m.round0,
                merges,
                dlimit,
                glimit,
            }),
            Event::Part(_)
            | Event::Finish { .. }
            | Event::RefineStart { .. }
            | Event::Refine(_) => {}
        }
    }

    fn is_silent(&self) -> bool {
        self.inner.is_silent()
    }
}
