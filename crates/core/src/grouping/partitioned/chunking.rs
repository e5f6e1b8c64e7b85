//! [`Chunking`]: the partitioned schedule's settings, with its two presets, the default
//! ([`Chunking::DEFAULT`]) and the fast path's ([`Chunking::FAST`]).

/// The split's parameters: chunk size δ, the reduction function's ε (AAC §3), the root's share
/// and how ranges are cut.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Chunking {
    /// AAC's δ: ranges of at most δ primitives are chunks, chunks keep f(δ) bodies, and f is
    /// scaled by it; 0 = by the scene's size ([`Chunking::for_size`]), at least 2 otherwise.
    pub delta: u32,
    /// f(n) = ⌈c·n^(1/2 − ε)⌉ with c = δ^(1/2 + ε)/2, in [0, 1/2].
    pub epsilon: f64,
    /// A node of n of the N primitives keeps at least ⌈top·n/N⌉ bodies, so the root's
    /// subproblem (the exact schedule's step) starts from about `top` bodies; 0 = AAC's f alone.
    /// A scene of at most 1.5 × `top` primitives is one subproblem (see [`Chunking::whole`]).
    pub top: u32,
    /// Ranges of at most this many primitives are cut by binned SAH on the best axis of
    /// their centres instead of at their highest differing Morton bit (`split`); 0 = Morton
    /// cuts throughout.
    pub sah_below: u32,
    /// Ranges of 3 up to this many primitives (at most [`Chunking::FEW_MAX`]) that are cut, not
    /// chunks, try every partition for the best binary tree over their leaves instead of the
    /// SAH sweep (`split`); 0 = the sweep. Only δ = 2 leaves such ranges to be cut.
    pub few: u32,
    /// Whether bodies with identical boxes that the Morton order puts side by side are merged
    /// in pairs before the split, and again while such pairs remain (`twins`): a mesh of
    /// double-sided faces is then split as one of half the size. The fast path sets it.
    pub twins: bool,
}

impl Chunking {
    /// The largest [`Chunking::few`]: the split tries every partition only in ranges of 3 or 4
    /// primitives (at most 7 partitions).
    pub const FEW_MAX: u32 = 4;

    /// The partitioned schedule's default: δ by the scene's size ([`Chunking::for_size`]), ε =
    /// 1/2, so that f(n) = δ/2: every node below the root share leaves δ/2 bodies and the nodes
    /// above it ⌈top·n/N⌉, with a root step of about 8,192 bodies; ranges of up to 256
    /// primitives are cut by SAH (docs/benchmarks.md has the measurements behind each value).
    pub const DEFAULT: Chunking = Chunking {
        delta: 0,
        epsilon: 0.5,
        top: 8192,
        sah_below: 256,
        few: 0,
        twins: false,
    };

    /// The fast path's split (`--fast`, bench method `fast`): the default's with a root share
    /// of 16 bodies and δ = 2, so that f(n) = 1: below the root share every node merges its two
    /// halves, and the tree there is the split's own (SAH cuts in ranges of up to 256
    /// primitives, every partition tried in ranges of 3 and 4, Morton cuts above), after
    /// identical neighbours are merged, under a root step of about 16 bodies; only scenes of at
    /// most 24 primitives are grouped whole. Its trees are further from the exact schedule's
    /// than the default's; the fast path's refinement (`refine::fast_for`) takes their SAH
    /// back down.
    pub const FAST: Chunking = Chunking {
        top: 16,
        delta: 2,
        few: 4,
        twins: true,
        ..Chunking::DEFAULT
    };

    /// δ for scenes of up to [`Chunking::BY_SIZE_UP_TO`] primitives when none is given:
    /// chunks of 4,096 primitives make most merges the exact run's own, so the tree stays
    /// close to the exact one's, at about the exact run's time on one thread spread over the
    /// threads (docs/benchmarks.md, "Chunks of δ primitives").
    pub const FAITHFUL_DELTA: u32 = 4096;

    /// δ for larger scenes when none is given.
    pub const LARGE_DELTA: u32 = 4;

    /// The most primitives that [`Chunking::FAITHFUL_DELTA`] applies to when δ is not given
    /// (2^18); larger scenes take [`Chunking::LARGE_DELTA`].
    pub const BY_SIZE_UP_TO: usize = 1 << 18;

    /// This chunking for a scene of `n` primitives: δ = 0 (by the scene's size) becomes
    /// [`Chunking::FAITHFUL_DELTA`] up to [`Chunking::BY_SIZE_UP_TO`] primitives and
    /// [`Chunking::LARGE_DELTA`] above; a given δ is kept.
    pub fn for_size(self, n: usize) -> Chunking {
        let delta = match self.delta {
            0 if n <= Self::BY_SIZE_UP_TO => Self::FAITHFUL_DELTA,
            0 => Self::LARGE_DELTA,
            d => d,
        };
        Chunking { delta, ..self }
    }

    /// Checks that δ is not 1, `few` at most [`Chunking::FEW_MAX`] and ε in [0, 1/2]; the
    /// errors name the CLI flags where there are some.
    pub fn check(&self) -> Result<(), String> {
        if self.delta == 1 {
            return Err(
                "--chunk-delta (δ) must be at least 2 (or 0: by the scene's size), got 1"
                    .to_string(),
            );
        }
        if self.few > Self::FEW_MAX {
            return Err(format!(
                "chunk_few must be at most {}, got {}",
                Self::FEW_MAX,
                self.few
            ));
        }
        if !(0.0..=0.5).contains(&self.epsilon) {
            return Err(format!(
                "--chunk-epsilon must be in [0, 0.5], got {}",
                self.epsilon
            ));
        }
        Ok(())
    }

    /// Whether a range of `size` primitives is a chunk: at most δ, and at least one.
    pub fn is_chunk(&self, size: u32) -> bool {
        size <= self.delta.max(1)
    }

    /// Whether a scene of `n` primitives is grouped as one subproblem, the exact schedule's
    /// step: when `n` ≤ 1.5 × `top`. The root step alone on about `top` bodies costs about what
    /// the exact schedule costs on all of them, so below this size the split would only
    /// approximate the tree for no gain.
    pub fn whole(&self, n: usize) -> bool {
        2 * n as u64 <= 3 * u64::from(self.top)
    }

    /// The bodies a node of `n` primitives leaves for the level above: f(n), at least 1.
    pub fn keep(&self, n: u32) -> u32 {
        let d = self.delta as f64;
        let c = d.powf(0.5 + self.epsilon) / 2.0;
        ((c * (n as f64).powf(0.5 - self.epsilon)).ceil() as u32).max(1)
    }
}

impl Default for Chunking {
    fn default() -> Self {
        Chunking::DEFAULT
    }
}
