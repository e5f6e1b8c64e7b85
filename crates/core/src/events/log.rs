//! Owned copies of events, and the log that keeps them all.

use super::{Event, Merge, Observer, Part, RefineParams, Step};

/// An owned copy of an [`Event`]: the event itself with a round start's active list moved
/// into `active` (the only borrowed field).
#[derive(Clone, Debug)]
pub struct OwnedEvent {
    event: Event<'static>,
    active: Vec<u32>,
}

impl OwnedEvent {
    /// Copies `e`.
    pub fn of(e: &Event<'_>) -> OwnedEvent {
        match *e {
            Event::RoundStart {
                round,
                dlimit,
                glimit,
                active,
                dormant,
                pairs,
            } => OwnedEvent {
                event: Event::RoundStart {
                    round,
                    dlimit,
                    glimit,
                    active: &[],
                    dormant,
                    pairs,
                },
                active: active.to_vec(),
            },
            Event::Merge(m) => OwnedEvent::plain(Event::Merge(m)),
            Event::Part(p) => OwnedEvent::plain(Event::Part(p)),
            Event::Refine(s) => OwnedEvent::plain(Event::Refine(s)),
            Event::RefineStart { params, sah } => {
                OwnedEvent::plain(Event::RefineStart { params, sah })
            }
            Event::Dormant {
                round,
                body,
                diameter,
            } => OwnedEvent::plain(Event::Dormant {
                round,
                body,
                diameter,
            }),
            Event::Doubling {
                round,
                merges,
                dlimit,
                glimit,
            } => OwnedEvent::plain(Event::Doubling {
                round,
                merges,
                dlimit,
                glimit,
            }),
            Event::Finish {
                root,
                rounds,
                merges,
            } => OwnedEvent::plain(Event::Finish {
                root,
                rounds,
                merges,
            }),
        }
    }

    fn plain(event: Event<'static>) -> OwnedEvent {
        OwnedEvent {
            event,
            active: Vec::new(),
        }
    }

    /// The event, borrowing the active list from this copy.
    pub fn event(&self) -> Event<'_> {
        match self.event {
            Event::RoundStart {
                round,
                dlimit,
                glimit,
                dormant,
                pairs,
                ..
            } => Event::RoundStart {
                round,
                dlimit,
                glimit,
                active: &self.active,
                dormant,
                pairs,
            },
            e => e,
        }
    }
}

/// Collects an owned copy of every event; used by tests and by `replay --verify`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EventLog {
    /// Every merge, in order.
    pub merges: Vec<Merge>,
    /// (round, dlimit, glimit, active count, dormant count, eligible pairs) per round start.
    pub rounds: Vec<(u32, f64, f64, u32, u32, u64)>,
    /// Bodies that went dormant, with their round.
    pub dormant: Vec<(u32, u32)>,
    /// (round, merges, new dlimit, new glimit) per doubling.
    pub doublings: Vec<(u32, u32, f64, f64)>,
    /// Root id once finished.
    pub root: Option<u32>,
    /// Every part announced, in order.
    pub parts: Vec<Part>,
    /// The refinement's parameters and starting SAH, if one ran.
    pub refine_start: Option<(RefineParams, f64)>,
    /// Every refinement step, in order.
    pub refine: Vec<Step>,
}

impl Observer for EventLog {
    fn on_event(&mut self, event: &Event<'_>) {
        match *event {
            Event::RoundStart {
                round,
                dlimit,
                glimit,
                active,
                dormant,
                pairs,
            } => self
                .rounds
                .push((round, dlimit, glimit, active.len() as u32, dormant, pairs)),
            Event::Merge(m) => self.merges.push(m),
            Event::Dormant { round, body, .. } => self.dormant.push((round, body)),
            Event::Doubling {
                round,
                merges,
                dlimit,
                glimit,
            } => self.doublings.push((round, merges, dlimit, glimit)),
            Event::Finish { root, .. } => self.root = Some(root),
            Event::Part(p) => self.parts.push(p),
            Event::RefineStart { params, sah } => self.refine_start = Some((params, sah)),
            Event::Refine(s) => self.refine.push(s),
        }
    }
}
