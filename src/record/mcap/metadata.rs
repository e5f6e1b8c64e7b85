//! The `wraptree` and `wraptree.timing` metadata records: what makes a recording
//! self-contained for a bug report, and how `replay` reads the run back.
//!
//! Every value is a string; numbers use Rust's shortest round-trip formatting, so parsing
//! them gives back the exact `f64`.

use crate::grouping::partitioned::Chunking;
use crate::grouping::{CostMeasure, Mode, PSet, Pregroup, ResolvedParams, Schedule, Weights};
use crate::record::{Detail, FORMAT_VERSION, Outcome, RunInfo};
use crate::refine::RefineParams;
use anyhow::{Context, Result, anyhow};
use clap::ValueEnum;
use std::collections::BTreeMap;

/// Name of the run metadata record (no wall-clock values).
pub const RUN: &str = "wraptree";
/// Name of the metadata record holding wall-clock values (omitted by reproducible recordings).
pub const TIMING: &str = "wraptree.timing";

/// Keys of the `wraptree` record, in the order `docs/recordings.md` ("Metadata") lists them.
pub const KEYS: &[&str] = &[
    "version",
    "format_version",
    "git_commit",
    "a",
    "b",
    "c",
    "dlimit0",
    "glimit0",
    "pset",
    "seed",
    "schedule",
    "pregroup",
    "instancing",
    "cost",
    "detail",
    "scene",
    "scene_file",
    "scene_sha256",
    "polyhedra",
    "strict",
    "primitives",
    "rounds",
    "merges",
    "depth_max",
    "depth_mean",
    "complete",
    "log_time",
];

/// Keys the `wraptree` record adds when the run stopped before the root (`complete` =
/// `false`): `stop_reason` is `interrupted` (Ctrl-C/SIGTERM), `max-seconds`, `max-pairs`, or
/// `unknown`; `stop_eligible_pairs` is the number of eligible pairs the round-start scans had
/// found (with a known reason). `merges` and `rounds` are then the merges made and the rounds
/// announced.
pub const STOP_KEYS: &[&str] = &["stop_reason", "stop_eligible_pairs"];

/// Keys the `wraptree` record adds about loading the scene: `up` (`y` or `z`) when the scene
/// was loaded with an up axis (`--up`); without it `replay` loads the embedded file with its
/// format's own.
pub const LOAD_KEYS: &[&str] = &["up"];

/// Keys the `wraptree` record adds for the partitioned schedule ([`Chunking`]): its chunk size
/// δ as the run used it, the reduction function's ε (`--chunk-epsilon`), the root's share
/// `top` (`--chunk-top`), the SAH cuts' range size (`--chunk-sah`), the largest range cut by
/// trying every partition (4 on the fast path, else 0) and whether identical neighbours were
/// merged first (`true` on the fast path), all read back by `replay`.
pub const PARTITIONED_KEYS: &[&str] = &[
    "chunk_delta",
    "chunk_epsilon",
    "chunk_top",
    "chunk_sah",
    "chunk_few",
    "chunk_twins",
];

/// One value a recording without `format_version` leaves out: `(key, value, whether it
/// applies to the record)`.
type LegacyDefault = (&'static str, &'static str, fn(&Record) -> bool);

/// The values recordings without `format_version` (made before it existed) leave out, each
/// the setting they were made with. These recordings are read by filling them in
/// ([`current_form`]); it is the only place that knows older forms.
const LEGACY_DEFAULTS: &[LegacyDefault] = &[
    // Made before modes existed: the default mode.
    ("schedule", "exact", always),
    ("pregroup", "none", always),
    ("instancing", "false", always),
    ("cost", "diameter", always),
    // Partitioned runs made before these keys: the root share's default, δ = 4, the
    // default ε, Morton cuts throughout, sweeps only and no identical neighbours merged.
    ("chunk_top", "8192", partitioned),
    ("chunk_delta", "4", partitioned),
    ("chunk_epsilon", "0.5", partitioned),
    ("chunk_sah", "0", partitioned),
    ("chunk_few", "0", partitioned),
    ("chunk_twins", "false", partitioned),
    // Refined runs made before treelet roots had a size bound: by the tree's size.
    ("refine_treelet_min", "0", refined),
    // Stopped runs made before the reason was written.
    ("stop_reason", "unknown", incomplete),
];

/// A `wraptree` metadata record.
type Record = BTreeMap<String, String>;

fn always(_: &Record) -> bool {
    true
}

fn partitioned(m: &Record) -> bool {
    m.get("schedule").map(String::as_str) == Some("partitioned")
}

fn refined(m: &Record) -> bool {
    m.contains_key("refine")
}

fn incomplete(m: &Record) -> bool {
    m.get("complete").map(String::as_str) == Some("false")
}

/// The record `m` in the current form: as it is with the current `format_version`; without
/// one (older recordings), with the legacy defaults (`LEGACY_DEFAULTS`) filled in and the older
/// spellings of two settings rewritten (`refine` = `reinsert`, refinement without treelet
/// passes; `chunk_max`, which was 0 = δ, dropped). A newer `format_version`, or an older run this version cannot
/// re-run (chunks of fewer than δ primitives), is one error line.
pub fn current_form(mut m: Record) -> Result<Record> {
    if let Some(v) = m.get("format_version") {
        let v: u32 = v
            .parse()
            .map_err(|_| anyhow!("`{RUN}` metadata has a bad `format_version`: {v:?}"))?;
        if v > FORMAT_VERSION {
            return Err(anyhow!(
                "the recording's format_version is {v}, newer than this wraptree reads \
                 ({FORMAT_VERSION}): read it with a newer wraptree"
            ));
        }
        return Ok(m);
    }
    // `chunk_max` was always 0 (= δ) but in runs made before it was written.
    if partitioned(&m) && m.remove("chunk_max").as_deref() != Some("0") {
        return Err(anyhow!(
            "`{RUN}` metadata: the run cut its split into chunks of fewer than δ primitives \
             (no `chunk_max` = 0), which this wraptree no longer does"
        ));
    }
    if m.get("refine").map(String::as_str) == Some("reinsert") {
        m.insert("refine".into(), "treelet+reinsert".into());
        m.insert(
            "refine_treelet".into(),
            RefineParams::default().treelet.to_string(),
        );
        m.insert("refine_treelet_passes".into(), "0".into());
    }
    for (key, value, applies) in LEGACY_DEFAULTS {
        if !m.contains_key(*key) && applies(&m) {
            m.insert((*key).into(), (*value).into());
        }
    }
    m.insert("format_version".into(), FORMAT_VERSION.to_string());
    Ok(m)
}

/// Keys the `wraptree` record adds when a cover is logged (`cover_budget` only for a cover
/// asked for by budget).
pub const COVER_KEYS: &[&str] = &[
    "cover_tolerance",
    "cover_budget",
    "cover_size",
    "cover_max_error",
];

/// Keys the `wraptree` record adds when the tree was refined (`record --refine`): `refine` =
/// `treelet+reinsert` (the method; `reinsert` in recordings without treelet passes), its
/// `refine_passes`, `refine_batch`, `refine_treelet`, `refine_treelet_passes` and
/// `refine_treelet_min` (what `replay --verify` re-runs; a recording without the last roots its
/// treelets by the tree's size, 0), the moves kept (`refine_steps`) and the SAH before and
/// after. `depth_max` and
/// `depth_mean` and the levels are then the refined tree's.
pub const REFINE_KEYS: &[&str] = &[
    "refine",
    "refine_passes",
    "refine_batch",
    "refine_treelet",
    "refine_treelet_passes",
    "refine_treelet_min",
    "refine_steps",
    "refine_sah_before",
    "refine_sah_after",
];

/// What the metadata says about a refinement run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefineSummary {
    /// Its parameters.
    pub params: RefineParams,
    /// Moves kept.
    pub steps: u32,
    /// SAH of the grouping's tree.
    pub sah_before: f64,
    /// SAH of the refined tree.
    pub sah_after: f64,
}

/// Adds the [`REFINE_KEYS`] of `r` to a `wraptree` record.
pub fn put_refine(m: &mut BTreeMap<String, String>, r: &RefineSummary) {
    for (k, v) in [
        ("refine", "treelet+reinsert".to_string()),
        ("refine_passes", r.params.passes.to_string()),
        ("refine_batch", r.params.batch.to_string()),
        ("refine_treelet", r.params.treelet.to_string()),
        ("refine_treelet_passes", r.params.treelet_passes.to_string()),
        ("refine_treelet_min", r.params.treelet_min.to_string()),
        ("refine_steps", r.steps.to_string()),
        ("refine_sah_before", r.sah_before.to_string()),
        ("refine_sah_after", r.sah_after.to_string()),
    ] {
        m.insert(k.to_string(), v);
    }
}

/// The refinement the record names, if any (a recording without the `refine` key was not
/// refined); `m` in the current form ([`current_form`]).
pub fn refine(m: &BTreeMap<String, String>) -> Result<Option<RefineSummary>> {
    match m.get("refine").map(String::as_str) {
        None => Ok(None),
        Some("treelet+reinsert") => {
            let params = RefineParams {
                passes: parse(m, "refine_passes")?,
                batch: parse(m, "refine_batch")?,
                treelet: parse(m, "refine_treelet")?,
                treelet_passes: parse(m, "refine_treelet_passes")?,
                treelet_min: parse(m, "refine_treelet_min")?,
            };
            params
                .check()
                .map_err(|e| anyhow!("metadata parameter {e}"))?;
            Ok(Some(RefineSummary {
                params,
                steps: parse(m, "refine_steps")?,
                sah_before: parse(m, "refine_sah_before")?,
                sah_after: parse(m, "refine_sah_after")?,
            }))
        }
        Some(v) => Err(anyhow!("`{RUN}` metadata has a bad `refine`: {v:?}")),
    }
}

/// Key the `wraptree` record adds for a finished run recorded with levels: the number of
/// `/levels/<d>` topics written (d = 0 up to it, exclusive; `depth_max + 1` with
/// `record --all-levels`).
pub const LEVELS_WRITTEN: &str = "levels_written";

/// How log times map to grouping steps (also stored under `log_time`).
pub const LOG_TIME: &str = "scene and attachment at 0 ms; the k-th grouping or refinement event (k = 1, 2, ...) at k ms; \
     /levels/<d> at (events + 1 + d) ms; /cover at (events + 2 + depth_max) ms";

fn value_name<T: ValueEnum>(v: &T) -> String {
    v.to_possible_value()
        .map(|p| p.get_name().to_string())
        .unwrap_or_default()
}

/// The `wraptree` record of a run. `depth_max`/`depth_mean` are present only for a finished
/// grouping, and `complete` is `"false"` when it is missing (a stopped run, with the
/// [`STOP_KEYS`]). With a cover:
/// `cover_tolerance` (absolute), `cover_budget` (when asked by budget), `cover_size` and
/// `cover_max_error`.
pub fn run_record(info: &RunInfo<'_>, outcome: &Outcome<'_>) -> BTreeMap<String, String> {
    let p = info.params;
    let mut m = BTreeMap::new();
    let mut put = |k: &str, v: String| {
        m.insert(k.to_string(), v);
    };
    put("version", env!("CARGO_PKG_VERSION").to_string());
    put("format_version", FORMAT_VERSION.to_string());
    put(
        "git_commit",
        option_env!("WRAPTREE_GIT_COMMIT")
            .unwrap_or("unknown")
            .to_string(),
    );
    put("a", p.weights.a.to_string());
    put("b", p.weights.b.to_string());
    put("c", p.weights.c.to_string());
    put("dlimit0", p.dlimit0.to_string());
    put("glimit0", p.glimit0.to_string());
    put("pset", value_name(&p.pset));
    put("seed", p.seed.map_or("none".to_string(), |s| s.to_string()));
    put("schedule", p.mode.schedule.name().to_string());
    put("pregroup", value_name(&p.mode.pregroup));
    put("instancing", p.mode.instancing.to_string());
    put("cost", value_name(&p.mode.cost));
    if let Schedule::Partitioned(c) = &p.mode.schedule {
        put("chunk_delta", c.delta.to_string());
        put("chunk_epsilon", c.epsilon.to_string());
        put("chunk_top", c.top.to_string());
        put("chunk_sah", c.sah_below.to_string());
        put("chunk_few", c.few.to_string());
        put("chunk_twins", c.twins.to_string());
    }
    put("detail", value_name(&info.detail));
    put("scene", info.scene.name.clone());
    put("scene_file", info.source.file_name.clone());
    put("scene_sha256", info.source.sha256.clone());
    put("polyhedra", info.source.options.polyhedra.to_string());
    put("strict", info.source.options.strict.to_string());
    if let Some(up) = info.source.options.up {
        put("up", up.name().to_string());
    }
    put("primitives", info.scene.len().to_string());
    put("rounds", outcome.rounds.to_string());
    put("merges", outcome.merges.to_string());
    if let Some(g) = outcome.grouping {
        put("depth_max", g.tree.depth_max().to_string());
        put("depth_mean", g.tree.depth_mean().to_string());
    }
    if let Some(c) = &outcome.cover {
        put("cover_tolerance", c.cover.tolerance.to_string());
        if let Some(k) = c.budget {
            put("cover_budget", k.to_string());
        }
        put("cover_size", c.cover.nodes.len().to_string());
        put("cover_max_error", c.cover.max_error().to_string());
    }
    put("complete", outcome.grouping.is_some().to_string());
    if outcome.grouping.is_none() {
        let reason = outcome.stopped.map_or("unknown", |s| s.reason.name());
        put("stop_reason", reason.to_string());
        if let Some(s) = outcome.stopped {
            put("stop_eligible_pairs", s.eligible_pairs.to_string());
        }
    }
    put("log_time", LOG_TIME.to_string());
    m
}

/// The `wraptree.timing` record: wall-clock grouping time.
pub fn timing_record(outcome: &Outcome<'_>) -> BTreeMap<String, String> {
    BTreeMap::from([("seconds".to_string(), outcome.seconds.to_string())])
}

/// Reads one key of the `wraptree` record.
pub fn get<'m>(m: &'m BTreeMap<String, String>, key: &str) -> Result<&'m str> {
    m.get(key)
        .map(String::as_str)
        .ok_or_else(|| anyhow!("`{RUN}` metadata lacks `{key}`"))
}

/// Parses one key of the `wraptree` record.
pub fn parse<T: std::str::FromStr>(m: &BTreeMap<String, String>, key: &str) -> Result<T> {
    let v = get(m, key)?;
    v.parse()
        .map_err(|_| anyhow!("`{RUN}` metadata has a bad `{key}`: {v:?}"))
}

fn parse_enum<T: ValueEnum>(m: &BTreeMap<String, String>, key: &str) -> Result<T> {
    let v = get(m, key)?;
    T::from_str(v, false).map_err(|_| anyhow!("`{RUN}` metadata has a bad `{key}`: {v:?}"))
}

/// The run's parameters, exactly as recorded; `m` in the current form ([`current_form`]).
pub fn params(m: &BTreeMap<String, String>) -> Result<ResolvedParams> {
    let seed = match get(m, "seed")? {
        "none" => None,
        _ => Some(parse::<u64>(m, "seed")?),
    };
    let params = ResolvedParams {
        weights: Weights {
            a: parse(m, "a")?,
            b: parse(m, "b")?,
            c: parse(m, "c")?,
        },
        dlimit0: parse(m, "dlimit0")?,
        glimit0: parse(m, "glimit0")?,
        pset: parse_enum::<PSet>(m, "pset")?,
        seed,
        mode: mode(m)?,
    };
    params
        .check()
        .map_err(|e| anyhow::anyhow!("metadata parameter {e}"))?;
    Ok(params)
}

/// The run's [`Mode`], its schedule with its [`Chunking`].
fn mode(m: &BTreeMap<String, String>) -> Result<Mode> {
    let schedule = match get(m, "schedule")? {
        "exact" => Schedule::Exact,
        "partitioned" => Schedule::Partitioned(Chunking {
            delta: parse(m, "chunk_delta")?,
            epsilon: parse(m, "chunk_epsilon")?,
            top: parse(m, "chunk_top")?,
            sah_below: parse(m, "chunk_sah")?,
            few: parse(m, "chunk_few")?,
            twins: parse(m, "chunk_twins")?,
        }),
        v => return Err(anyhow!("`{RUN}` metadata has a bad `schedule`: {v:?}")),
    };
    Ok(Mode {
        schedule,
        pregroup: parse_enum::<Pregroup>(m, "pregroup")?,
        instancing: parse(m, "instancing")?,
        cost: parse_enum::<CostMeasure>(m, "cost")?,
    })
}

/// Why the recorded run stopped before the root: `None` for a complete recording; `m` in the
/// current form ([`current_form`]).
pub fn stop_reason(m: &BTreeMap<String, String>) -> Option<&str> {
    match m.get("complete").map(String::as_str) {
        Some("false") => m.get("stop_reason").map(String::as_str),
        _ => None,
    }
}
/// The recording's detail level.
pub fn detail(m: &BTreeMap<String, String>) -> Result<Detail> {
    parse_enum(m, "detail").context("reading the detail level")
}
