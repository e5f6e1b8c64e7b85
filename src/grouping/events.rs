//! Typed events of the grouping phase and the one observer interface recorders subscribe to.
//!
//! The algorithm calls [`Observer::on_event`] at each step; it knows nothing about Rerun or
//! MCAP. The unit observer `()` ignores everything and is inlined away, so grouping without a
//! listener costs nothing.

use crate::geom::Aabb;

/// One merge of step 4(a): bodies `a` and `b` become the new body `new`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Merge {
    /// 0-based merge index; the new body's id is `n + step`.
    pub step: u32,
    /// Round (number of DLimit doublings so far) in which the merge happened.
    pub round: u32,
    /// First merged body (the smaller id).
    pub a: u32,
    /// Second merged body (the larger id).
    pub b: u32,
    /// Id of the new body.
    pub new: u32,
    /// AABB of the new body.
    #[serde(serialize_with = "ser_aabb")]
    pub aabb: Aabb,
    /// Diameter of the new body.
    pub diameter: f64,
    /// Fill = new diameter / (diameter a + diameter b).
    pub fill: f64,
    /// Balance = greater ratio of the children's diameters (≥ 1).
    pub balance: f64,
    /// Cost = diameter^A × (B·Fill + C·Balance).
    pub cost: f64,
    /// Entries left in MPairs after the pop.
    pub queue_len: u32,
    /// Whether the new body obeys DLimit (active) or went dormant (step 4c).
    pub active: bool,
}

fn ser_aabb<S: serde::Serializer>(b: &Aabb, s: S) -> Result<S::Ok, S::Error> {
    use serde::Serialize;
    [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z].serialize(s)
}

/// What a [`Part`] of a grouping run groups.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum PartKind {
    /// A chunk of the partitioned schedule: a set of bodies at `level` of the top-down split
    /// (0 = the whole scene), grouped until at most `keep` of them remain.
    Chunk {
        /// Depth of the chunk in the split (0 = the top).
        level: u32,
        /// Bodies left ungrouped for the level above (1 at the top).
        keep: u32,
    },
    /// A component (pre-grouping): its primitives are grouped on their own.
    Component {
        /// Index of the component in the documented component order.
        index: u32,
    },
    /// A rigid copy of component `of` (instancing): it takes the representative's Subset Tree
    /// shape; `rotation` (row-major 3×3) and `translation` map the representative onto it.
    Copy {
        /// Index of the component this one copies.
        of: u32,
        /// Row-major rotation matrix.
        rotation: [f64; 9],
        /// Translation applied after the rotation.
        translation: [f64; 3],
    },
    /// The top level: the roots of the parts (and any bodies left out of parts) grouped together.
    Top,
}

/// A part of a grouping run: the merges that follow it, up to the next `Part` or `Finish`,
/// group the bodies of this part (a chunk of the partitioned schedule, a component, a copy, or
/// the top level).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Part {
    /// 0-based index of the part in the run, in event order.
    pub id: u32,
    /// What the part groups.
    pub kind: PartKind,
    /// Number of bodies the part starts from.
    pub bodies: u32,
    /// Merge step of the part's first merge (= merges made before it).
    pub first_step: u32,
}

impl std::fmt::Display for Part {
    /// One log line, e.g. `part 3: chunk at level 2 (12 bodies → 4) from merge 57`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "part {}: ", self.id)?;
        match self.kind {
            PartKind::Chunk { level, keep } => write!(
                f,
                "chunk at level {level} ({} bodies → {keep})",
                self.bodies
            )?,
            PartKind::Component { index } => {
                write!(f, "component {index} ({} primitives)", self.bodies)?
            }
            PartKind::Copy {
                of, translation, ..
            } => write!(
                f,
                "copy of component {of} ({} primitives, moved by [{:.4}, {:.4}, {:.4}])",
                self.bodies, translation[0], translation[1], translation[2]
            )?,
            PartKind::Top => write!(f, "top level ({} bodies)", self.bodies)?,
        }
        write!(f, " from merge {}", self.first_step)
    }
}

/// A step of the grouping phase.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event<'a> {
    /// A part of the run starts (partitioned schedule, pre-grouping, instancing); the plain
    /// §2.2 run emits none.
    Part(Part),
    /// Step 2–3: a round starts with these limits and sets.
    RoundStart {
        /// Round index (0 for the first).
        round: u32,
        /// DLimit of this round.
        dlimit: f64,
        /// GLimit of this round.
        glimit: f64,
        /// Active bodies (parent-less, diameter ≤ DLimit), sorted by id.
        active: &'a [u32],
        /// Number of dormant bodies.
        dormant: u32,
        /// Eligible pairs found by the voxel scan (the literal MPairs length).
        pairs: u64,
    },
    /// Step 4(a): a pair was popped and merged.
    Merge(Merge),
    /// Step 4(c): a new body exceeds DLimit and goes dormant until a later round.
    Dormant {
        /// Round index.
        round: u32,
        /// The body.
        body: u32,
        /// Its diameter.
        diameter: f64,
    },
    /// Step 5: MPairs is empty; DLimit and GLimit double.
    Doubling {
        /// Round that just ended.
        round: u32,
        /// Merges made in that round.
        merges: u32,
        /// New DLimit.
        dlimit: f64,
        /// New GLimit.
        glimit: f64,
    },
    /// A refinement run of the finished tree starts (`record --refine`, see
    /// [`crate::refine`]); comes after `Finish`.
    RefineStart {
        /// Its parameters.
        params: crate::refine::RefineParams,
        /// SAH of the tree before refinement.
        sah: f64,
    },
    /// The refinement kept one step (a rebuilt treelet or a move, see
    /// [`crate::refine::StepKind`]); one per kept step, after `RefineStart`.
    Refine(crate::refine::Step),
    /// The root exists; grouping is over.
    Finish {
        /// Root body id.
        root: u32,
        /// Number of rounds run.
        rounds: u32,
        /// Number of merges (N − 1).
        merges: u32,
    },
}

/// Receives every [`Event`] of a grouping run, in order.
pub trait Observer {
    /// Called once per event.
    fn on_event(&mut self, event: &Event<'_>);

    /// Whether this observer ignores every event, so that the algorithm may skip preparing
    /// them (the partitioned schedule and pre-grouping then buffer no events of their parallel
    /// parts). Default: false.
    fn is_silent(&self) -> bool {
        false
    }
}

/// The silent observer.
impl Observer for () {
    #[inline(always)]
    fn on_event(&mut self, _: &Event<'_>) {}

    fn is_silent(&self) -> bool {
        true
    }
}

impl<O: Observer + ?Sized> Observer for &mut O {
    #[inline]
    fn on_event(&mut self, event: &Event<'_>) {
        (**self).on_event(event)
    }

    fn is_silent(&self) -> bool {
        (**self).is_silent()
    }
}

/// An optional observer (e.g. a progress bar shown only on a terminal).
impl<O: Observer> Observer for Option<O> {
    #[inline]
    fn on_event(&mut self, event: &Event<'_>) {
        if let Some(o) = self {
            o.on_event(event)
        }
    }

    fn is_silent(&self) -> bool {
        self.as_ref().is_none_or(O::is_silent)
    }
}

/// Forwards each event to two observers (e.g. a recorder and a progress bar).
pub struct Tee<A, B>(pub A, pub B);

impl<A: Observer, B: Observer> Observer for Tee<A, B> {
    #[inline]
    fn on_event(&mut self, event: &Event<'_>) {
        self.0.on_event(event);
        self.1.on_event(event);
    }

    fn is_silent(&self) -> bool {
        self.0.is_silent() && self.1.is_silent()
    }
}

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
    pub refine_start: Option<(crate::refine::RefineParams, f64)>,
    /// Every refinement step, in order.
    pub refine: Vec<crate::refine::Step>,
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
