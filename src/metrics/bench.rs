//! The measurements of `wraptree bench` besides the builder × wrapper comparison
//! ([`compare`](super::compare)): the targets table against obvhs PLOC and parry Binned
//! ([`target_row`]) and what recording costs ([`record_cost`]).

use super::timing::fastest;
use crate::grouping::{self, Params};
use crate::peers::{self, Method};
use crate::query::{self, Bv, Workload};
use crate::record::{Detail, RecordOptions, Written, record};
use crate::scene::spec::as_loaded;
use crate::scene::{LoadOptions, Loaded, load_path};
use crate::scene::{Scene, generate};
use crate::stop::Stop;
use anyhow::Result;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The best wall time of `repeat` (at least one) runs of `f`, in seconds.
pub fn best_of(repeat: u32, mut f: impl FnMut()) -> f64 {
    (0..repeat.max(1))
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The scenes of the targets table: soups of 10^4 and (up to `max_soup`) 10^5 and 10^6
/// triangles, 44 robot bases, and every OBJ in the crate's `scenes/` folder.
pub fn target_scenes(max_soup: usize) -> Result<Vec<Scene>> {
    let mut cases: Vec<Scene> = vec![generate::soup(10_000, 1)];
    cases.push(generate::replicate(&generate::robot_base(), 44, 1));
    for n in [100_000, 1_000_000] {
        if n <= max_soup {
            cases.push(generate::soup(n, 1));
        }
    }
    let bundled = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut meshes: Vec<_> = std::fs::read_dir(&bundled)
        .map(|d| d.filter_map(|e| Some(e.ok()?.path())).collect())
        .unwrap_or_default();
    meshes.retain(|p: &PathBuf| p.extension().is_some_and(|e| e == "obj"));
    meshes.sort();
    for m in meshes {
        let mut s = load_path(&m, &LoadOptions::default())?.scene;
        s.name = m.file_stem().unwrap_or_default().to_string_lossy().into();
        cases.push(s);
    }
    Ok(cases)
}

/// One scene of the targets table.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetRow {
    /// Scene name.
    pub scene: String,
    /// Primitives.
    pub n: usize,
    /// Best grouping time (s).
    pub group_seconds: f64,
    /// Best obvhs PLOC build time (s).
    pub ploc_seconds: f64,
    /// Best parry Binned build time (s).
    pub binned_seconds: f64,
    /// SAH of the grouping tree / parry Binned's.
    pub sah_ratio: f64,
    /// Node tests per query (AABB BVs, standard workload) of the grouping tree / parry
    /// Binned's.
    pub query_ratio: f64,
    /// Node tests per contact query (AABB BVs, the standard workload's touching poses) of the
    /// grouping tree / parry Binned's.
    pub contact_ratio: f64,
    /// Largest depth of the grouping tree.
    pub depth: u32,
    /// Process peak RSS after the case, if known.
    pub peak_rss_bytes: Option<u64>,
}

/// Measures `scene` for the targets table: the fastest builds in `repeat` rounds (at most 2 from
/// 10^6 primitives; [`fastest`]) of the grouping phase, obvhs PLOC and parry Binned among
/// others, and their trees' SAH and query cost.
pub fn target_row(scene: &Scene, repeat: u32) -> Result<TargetRow> {
    Ok(target_rows(scene, repeat)?.0)
}

/// One measured build: the fastest of the rounds, its SAH and its node tests per query and per
/// contact query.
struct Measured {
    /// The build (its time is `built.seconds`).
    built: peers::Built,
    /// SAH of its tree.
    sah: f64,
    /// Node tests per query (AABB BVs, the standard workload).
    tests: f64,
    /// Node tests per contact query.
    contact: f64,
}

/// The fastest builds of `methods` on `scene` in `rounds` rounds ([`fastest`]; at most 2 from
/// 10^6 primitives), each with its SAH and node tests per query and per contact query on
/// `workload`, on the current rayon pool; in `methods`' order.
fn measure<const K: usize>(
    methods: [Method; K],
    scene: &Scene,
    rounds: u32,
    workload: &Workload,
) -> Result<[Measured; K]> {
    let rounds = if scene.len() >= 1_000_000 {
        rounds.min(2)
    } else {
        rounds
    };
    let built = fastest(&methods, scene, &Params::default(), rounds, &Stop::new())?;
    let measured: Vec<Measured> = built
        .into_iter()
        .map(|built| {
            let q = query::measure(&built.tree, scene, Bv::Aabb, workload);
            Measured {
                sah: super::sah(&built.tree),
                tests: super::compare::query_values(&q)[6],
                contact: q.contact.bv_tests,
                built,
            }
        })
        .collect();
    Ok(measured
        .try_into()
        .unwrap_or_else(|_| unreachable!("one build per method")))
}

/// Grouping + refinement against the best peer on one scene.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RefineRow {
    /// Scene name.
    pub scene: String,
    /// Refinement time alone (s).
    pub refine_seconds: f64,
    /// Grouping + refinement time (s).
    pub total_seconds: f64,
    /// Refinement time alone / obvhs PLOC build time.
    pub refine_per_ploc: f64,
    /// SAH / the best of parry Binned and obvhs PLOC + reinsertion.
    pub sah_per_best: f64,
    /// Node tests per query / the best of the same two.
    pub query_per_best: f64,
    /// Node tests per contact query / the best of the same two.
    pub contact_per_best: f64,
    /// The partitioned grouping + refinement: time (s).
    pub part_total_seconds: f64,
    /// Its refinement time alone / obvhs PLOC build time.
    pub part_refine_per_ploc: f64,
    /// Its SAH / the best peer's (as `sah_per_best`).
    pub part_sah_per_best: f64,
    /// Its node tests per query / the best peer's (as `query_per_best`).
    pub part_query_per_best: f64,
    /// Its node tests per contact query / the best peer's (as `contact_per_best`).
    pub part_contact_per_best: f64,
}

/// The §1.3 speed-ups (pre-grouping, instancing) on one scene and thread count, against obvhs
/// PLOC and the plain grouping.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SpeedupRow {
    /// Scene name.
    pub scene: String,
    /// The method.
    pub method: Method,
    /// Rayon threads.
    pub threads: usize,
    /// Best build time (s).
    pub seconds: f64,
    /// Time / obvhs PLOC's.
    pub per_ploc: f64,
    /// Time / the plain grouping's.
    pub per_grouping: f64,
    /// SAH / the plain grouping's.
    pub sah_ratio: f64,
    /// Node tests per query / the plain grouping's.
    pub query_ratio: f64,
    /// Largest depth.
    pub depth: u32,
    /// Volume of the depth-3 cut as boxes / the plain grouping's (NaN above 50,000 primitives).
    pub box8_ratio: f64,
    /// The same as convex hulls.
    pub hull8_ratio: f64,
}

/// Measures `scene` for the three targets tables: the main row, grouping + refinement against
/// the best peer, and the pre-grouped and instanced groupings on 1 and 2 threads.
pub fn target_rows(scene: &Scene, repeat: u32) -> Result<(TargetRow, RefineRow, Vec<SpeedupRow>)> {
    let n = scene.len();
    let workload = Workload::standard(scene, 1);
    let [plain, ploc, binned, refined, reinserted, part_refined] = measure(
        [
            Method::GROUPING,
            Method::OBVHS_PLOC,
            Method::PARRY_BINNED,
            Method::GROUPING_REFINE,
            Method::OBVHS_PLOC_REINSERT,
            Method::GROUPING_PARTITIONED_REFINE,
        ],
        scene,
        repeat,
        &workload,
    )?;
    let tp = ploc.built.seconds;
    // The best of parry Binned and PLOC + reinsertion, per measure.
    let best_sah = binned.sah.min(reinserted.sah);
    let best_tests = binned.tests.min(reinserted.tests);
    let best_contact = binned.contact.min(reinserted.contact);
    let refine = RefineRow {
        scene: scene.name.clone(),
        refine_seconds: refined.built.refine_seconds,
        total_seconds: refined.built.seconds,
        refine_per_ploc: refined.built.refine_seconds / tp,
        sah_per_best: refined.sah / best_sah,
        query_per_best: refined.tests / best_tests,
        contact_per_best: refined.contact / best_contact,
        part_total_seconds: part_refined.built.seconds,
        part_refine_per_ploc: part_refined.built.refine_seconds / tp,
        part_sah_per_best: part_refined.sah / best_sah,
        part_query_per_best: part_refined.tests / best_tests,
        part_contact_per_best: part_refined.contact / best_contact,
    };
    let (t, sah, qc) = (plain.built.seconds, plain.sah, plain.tests);
    let volumes = n <= 50_000;
    let vol = |b: &peers::Built| super::level_volume(&b.tree, scene, 3);
    let (box8, hull8) = if volumes {
        vol(&plain.built)
    } else {
        (1.0, 1.0)
    };
    let sped = [
        Method::GROUPING_PREGROUP,
        Method::GROUPING_INSTANCED,
        Method::GROUPING_OBJECTS,
    ];
    let mut on_threads = Vec::new();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?;
        on_threads.push((
            threads,
            pool.install(|| measure(sped, scene, repeat, &workload))?,
        ));
    }
    let mut sped_up = Vec::new();
    for i in 0..sped.len() {
        for (threads, measured) in &on_threads {
            let sped = &measured[i];
            let tm = sped.built.seconds;
            let (bm, hm) = if volumes {
                vol(&sped.built)
            } else {
                (f64::NAN, f64::NAN)
            };
            sped_up.push(SpeedupRow {
                scene: scene.name.clone(),
                method: sped.built.method,
                threads: *threads,
                seconds: tm,
                per_ploc: tm / tp,
                per_grouping: tm / t,
                sah_ratio: sped.sah / sah,
                query_ratio: sped.tests / qc,
                depth: sped.built.tree.depth_max(),
                box8_ratio: bm / box8,
                hull8_ratio: hm / hull8,
            });
        }
    }
    let row = TargetRow {
        scene: scene.name.clone(),
        n,
        group_seconds: t,
        ploc_seconds: tp,
        binned_seconds: binned.built.seconds,
        sah_ratio: sah / binned.sah,
        query_ratio: qc / binned.tests,
        contact_ratio: plain.contact / binned.contact,
        depth: plain.built.tree.depth_max(),
        peak_rss_bytes: super::peak_rss_bytes(),
    };
    Ok((row, refine, sped_up))
}

/// The scenes `bench --record` measures: lamps × 5 (3,130 polygons), robot bases × 44 (12,144)
/// and a 10^5-triangle soup.
pub fn record_scenes() -> [Scene; 3] {
    [
        generate::replicate(&generate::lamp(), 5, 1),
        generate::replicate(&generate::robot_base(), 44, 1),
        generate::soup(100_000, 1),
    ]
}

/// The details `bench --record` measures, in its table's order.
pub const RECORD_DETAILS: [Detail; 3] = [Detail::Levels, Detail::Merges, Detail::Full];

/// One line of `bench --record`: what recording one scene at one detail costs.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordCostRow {
    /// Scene name.
    pub scene: String,
    /// Primitives.
    pub n: usize,
    /// What was recorded.
    pub detail: Detail,
    /// The measured cost.
    pub cost: RecordCost,
    /// The fixed cost (s) of a 2-triangle recording at this detail.
    pub fixed_seconds: f64,
}

/// `bench --record`: [`record_cost`] of each of [`record_scenes`] at each of
/// [`RECORD_DETAILS`] (into a temporary directory), `repeat` pairs each; `on_row` sees each row
/// as it is measured. Returns the fixed costs (s) of a 2-triangle recording per detail.
pub fn record_costs(repeat: u32, mut on_row: impl FnMut(&RecordCostRow)) -> Result<[f64; 3]> {
    let dir = tempfile::tempdir()?;
    // The fixed cost of a recording: two triangles, one merge.
    let tiny = as_loaded(&generate::soup(2, 1))?;
    let mut fixed = [0.0; 3];
    for (f, &detail) in fixed.iter_mut().zip(&RECORD_DETAILS) {
        let prefix = dir.path().join(format!("fixed-{detail:?}"));
        *f = record_cost(&tiny, &Params::default(), detail, &prefix, repeat)?.record_seconds;
    }
    for scene in &record_scenes() {
        let loaded = as_loaded(scene)?;
        for (&detail, &fixed_seconds) in RECORD_DETAILS.iter().zip(&fixed) {
            let prefix = dir.path().join(format!("{}-{detail:?}", scene.name));
            on_row(&RecordCostRow {
                scene: scene.name.clone(),
                n: scene.len(),
                detail,
                cost: record_cost(&loaded, &Params::default(), detail, &prefix, repeat)?,
                fixed_seconds,
            });
        }
    }
    Ok(fixed)
}

/// `repeat` pairs of (grouping alone, grouping recorded) wall times for `loaded` with
/// `params`, each recorded run just after its grouping-only run so that a slow spell of the
/// machine weighs on both sides of a pair; and where the last recording went
/// (`PREFIX.rrd`/`.mcap`, replaced, reproducible, sphere Wrapper Trees).
pub fn record_pairs(
    loaded: &Loaded,
    params: &Params,
    detail: Detail,
    prefix: &Path,
    repeat: u32,
) -> Result<(Vec<(f64, f64)>, Written)> {
    let resolved = params.resolve(&loaded.scene);
    let opts = RecordOptions {
        detail,
        force: true,
        reproducible: true,
        ..RecordOptions::default()
    };
    let mut written = None;
    let pairs = (0..repeat.max(1))
        .map(|_| {
            let t_group = best_of(1, || {
                std::hint::black_box(grouping::group(&loaded.scene, params, ()));
            });
            let t_rec = best_of(1, || {
                written = Some(record(loaded, &resolved, prefix, &opts, ()));
            });
            (t_group, t_rec)
        })
        .collect();
    Ok((pairs, written.expect("ran at least once")?))
}

/// What recording one scene at one detail costs.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordCost {
    /// Best grouping-only time (s).
    pub group_seconds: f64,
    /// Best recorded time (s): grouping with both recorders listening, sphere tree, both files.
    pub record_seconds: f64,
    /// Median over the pairs of recorded / grouping-only time.
    pub median_ratio: f64,
    /// `.rrd` size in bytes.
    pub rrd_bytes: u64,
    /// `.mcap` size in bytes.
    pub mcap_bytes: u64,
}

/// Measures [`record_pairs`] of `loaded` with `params` at `detail` into `prefix`, `repeat`
/// times.
pub fn record_cost(
    loaded: &Loaded,
    params: &Params,
    detail: Detail,
    prefix: &Path,
    repeat: u32,
) -> Result<RecordCost> {
    let (pairs, w) = record_pairs(loaded, params, detail, prefix, repeat)?;
    let mut ratios: Vec<f64> = pairs.iter().map(|(g, r)| r / g).collect();
    ratios.sort_by(f64::total_cmp);
    let size = |p: &Path| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
    Ok(RecordCost {
        group_seconds: pairs.iter().map(|p| p.0).fold(f64::INFINITY, f64::min),
        record_seconds: pairs.iter().map(|p| p.1).fold(f64::INFINITY, f64::min),
        median_ratio: ratios[ratios.len() / 2],
        rrd_bytes: size(&w.rrd),
        mcap_bytes: size(&w.mcap),
    })
}
