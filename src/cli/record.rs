//! `wraptree record`: group a scene step by step and write `PREFIX.rrd` and `PREFIX.mcap`
//! ([`wraptree::record::record`]).

use super::group::{BudgetArgs, EXIT_INTERRUPTED, Progress};
use super::{GroupArgs, SceneArgs};
use anyhow::Result;
use clap::Args;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use wraptree::output::output_prefix;
use wraptree::record::live::{self, Live, LiveOptions, RerunLive};
use wraptree::record::mcap::Compression;
use wraptree::record::{Detail, RecordOptions, Written, record};
use wraptree::refine::RefineParams;
use wraptree::scene::Scene;
use wraptree::stop::Stop;
use wraptree::wrap::WrapperKind;
use wraptree::wrap::cover::solve::{CoverLimit, Tolerance};

/// Arguments of `wraptree record`.
#[derive(Args, Debug)]
pub struct RecordCmd {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    pub(super) group: GroupArgs,
    #[command(flatten)]
    limits: BudgetArgs,
    /// Output prefix: writes PREFIX.rrd and PREFIX.mcap [default: recordings/<scene stem>];
    /// the prefix's directory must exist.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// What to write: levels, merges, or full.
    #[arg(long, value_enum, default_value_t = Detail::Full)]
    detail: Detail,
    /// Replace existing recordings.
    #[arg(long)]
    force: bool,
    /// Leave wall-clock timing out of the .mcap so identical runs give identical bytes.
    #[arg(long)]
    reproducible: bool,
    /// Wrapper Trees logged with the levels, comma-separated: sphere, hull, box (aabb), obb.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "sphere")]
    wrapper: Vec<WrapperKind>,
    /// Also log the cover within this error (as `cover --tolerance`: a length, or P% of the
    /// scene diagonal) as one more level.
    #[arg(long, value_parser = Tolerance::parse, allow_negative_numbers = true, conflicts_with = "cover_budget")]
    cover_tolerance: Option<Tolerance>,
    /// Also log the best cover with at most K wrappers as one more level.
    #[arg(long, value_name = "K")]
    cover_budget: Option<usize>,
    /// Wrapper kinds the cover chooses from, comma-separated: sphere, box (or aabb), obb, hull.
    #[arg(long, default_value = "sphere,box,hull", value_delimiter = ',', value_parser = WrapperKind::parse)]
    cover_kinds: Vec<WrapperKind>,
    /// Compress the .mcap's chunks: zstd (smallest; `auto` is the same), lz4 (faster), or none
    /// (fastest to write and read, the scene attached uncompressed too).
    #[arg(long, value_enum, default_value_t = Compression::default())]
    mcap_compression: Compression,
    /// Write every level to the .mcap (default: from the root down to the last level whose cut
    /// is less than half leaves; the .rrd always has every level).
    #[arg(long)]
    all_levels: bool,
    #[command(flatten)]
    refine: RefineArgs,
    #[command(flatten)]
    live: LiveArgs,
}

/// The refinement of a recorded run (`record --refine`).
#[derive(Args, Debug, Clone, Copy)]
pub struct RefineArgs {
    /// Refine the finished tree (treelet restructuring, then reinsertion, see docs/method.md)
    /// and record each step on the `refine` timeline / `/refine/step` topic; the levels are then
    /// the refined tree's.
    #[arg(long)]
    pub refine: bool,
    /// Most refinement passes (with --refine) [default: 3; with --fast, the fast path's
    /// refinement for the scene's size: 2 from 1,024 primitives, 3 below].
    #[arg(long, requires = "refine")]
    refine_passes: Option<u32>,
    /// Fraction of the nodes searched in the first refinement pass, in (0, 1] (with --refine)
    /// [default: 0.1; with --fast, 0.07 from 16,384 primitives].
    #[arg(long, requires = "refine")]
    refine_batch: Option<f64>,
    /// Most leaves of a restructured treelet, 3 to 7 (with --refine) [default: 7; with --fast,
    /// 5].
    #[arg(long, requires = "refine")]
    refine_treelet: Option<u32>,
    /// Treelet restructuring passes before the reinsertion passes (with --refine; 0 = none)
    /// [default: 1; with --fast, 1 from 1,024 primitives, 0 below].
    #[arg(long, requires = "refine")]
    refine_treelet_passes: Option<u32>,
    /// Treelets are rooted only at nodes of at least this many leaves (with --refine; 0 = by
    /// the tree's size: 64 up to 65,536 leaves, more above) [default: 0; with --fast, 8].
    #[arg(long, requires = "refine")]
    refine_treelet_min: Option<u32>,
}

impl RefineArgs {
    /// The refinement's parameters with `--refine`: `base` with every refine flag given in its
    /// place.
    fn params(&self, base: RefineParams) -> Option<RefineParams> {
        self.refine.then(|| RefineParams {
            passes: self.refine_passes.unwrap_or(base.passes),
            batch: self.refine_batch.unwrap_or(base.batch),
            treelet: self.refine_treelet.unwrap_or(base.treelet),
            treelet_passes: self.refine_treelet_passes.unwrap_or(base.treelet_passes),
            treelet_min: self.refine_treelet_min.unwrap_or(base.treelet_min),
        })
    }
}

/// Watching the run live while the files are written (`record`, `replay --a/--b/--c`); see
/// docs/recordings.md, "Live viewing".
#[derive(Args, Debug, Clone)]
pub struct LiveArgs {
    /// Also stream the .rrd to a running Rerun viewer (or `rerun --serve-grpc`) at URL
    /// [default: rerun+http://127.0.0.1:9876/proxy].
    #[arg(long, value_name = "URL", num_args = 0..=1, require_equals = true,
          default_missing_value = live::DEFAULT_CONNECT_URL, conflicts_with_all = ["serve", "spawn"])]
    connect: Option<String>,
    /// Also serve the .rrd's stream from a gRPC server on IP:PORT, for Rerun viewers that connect
    /// during or after the run (`rerun --connect rerun+http://HOST:PORT/proxy`); after the run it
    /// keeps serving until Ctrl-C [default: 0.0.0.0:9876].
    #[arg(long, value_name = "IP:PORT", num_args = 0..=1, require_equals = true,
          default_missing_value = "0.0.0.0:9876", conflicts_with = "spawn")]
    serve: Option<SocketAddr>,
    /// With --serve: how much of the stream the server keeps for late viewers (e.g. 2GB, 25%
    /// of the RAM, unlimited); above it the oldest merges are dropped first, then the scene;
    /// the layout is always kept.
    #[arg(long, value_name = "LIMIT", default_value = "25%", requires = "serve")]
    serve_memory_limit: String,
    /// Also start a Rerun viewer (`rerun` on PATH; one already listening on port 9876 is
    /// reused) and stream the .rrd to it.
    #[arg(long)]
    spawn: bool,
    /// Also serve the .mcap's topics over the Foxglove WebSocket protocol on HOST:PORT (port 0:
    /// any free port), during and after the run; after the run it keeps serving until Ctrl-C
    /// [default: 127.0.0.1:8765].
    #[arg(long, value_name = "HOST:PORT", num_args = 0..=1, require_equals = true,
          default_missing_value = live::foxglove::DEFAULT_ADDR)]
    foxglove_ws: Option<String>,
    /// With --foxglove-ws: wait for a Foxglove client to connect before the run starts (a
    /// client gets no history, only the latest message of each topic).
    #[arg(long, requires = "foxglove_ws")]
    foxglove_wait: bool,
}

impl LiveArgs {
    /// Whether any live flag is given.
    pub fn any(&self) -> bool {
        self.connect.is_some() || self.serve.is_some() || self.spawn || self.foxglove_ws.is_some()
    }

    /// Starts what the flags ask for, prints where each stream goes, and with --foxglove-wait
    /// waits for a Foxglove client (or Ctrl-C, which then stops the run at once).
    pub fn start(&self, stop: &AtomicBool) -> Result<Live> {
        let rerun = match (&self.connect, self.serve, self.spawn) {
            (Some(url), _, _) => Some(RerunLive::Connect(url.clone())),
            (_, Some(addr), _) => Some(RerunLive::Serve {
                addr,
                memory_limit: self.serve_memory_limit.clone(),
            }),
            (_, _, true) => Some(RerunLive::Spawn),
            _ => None,
        };
        let opts = LiveOptions {
            rerun,
            foxglove: self.foxglove_ws.clone(),
            ..LiveOptions::default()
        };
        let live = Live::start(&opts)?;
        for line in live.describe() {
            println!("{line}");
        }
        if self.foxglove_wait {
            println!("live Foxglove: waiting for a client to connect before the run");
            live.wait_for_foxglove_client(stop);
        }
        Ok(live)
    }
}

/// After the run: lets the live streams hand over what they hold, warns about what did not get
/// through, and, with a server (--serve, --foxglove-ws) and no Ctrl-C so far, keeps serving
/// until Ctrl-C or SIGTERM.
pub fn after_run(live: &Live, stop: &AtomicBool) {
    if !live.is_on() {
        return;
    }
    for line in live.finish() {
        eprintln!("warning: {line}");
    }
    if live.serves() && !stop.load(Ordering::Relaxed) {
        println!("live: the run is recorded; still serving it until Ctrl-C");
        live.keep_serving(stop);
    }
}

/// Success for a finished grouping, else the stop's exit code (3 for a limit, 130 for
/// Ctrl-C/SIGTERM).
pub fn exit_code(w: &Written) -> ExitCode {
    match (&w.grouping, &w.stopped) {
        (Some(_), _) => ExitCode::SUCCESS,
        (None, Some(s)) => BudgetArgs::exit_code(s.reason),
        (None, None) => ExitCode::from(EXIT_INTERRUPTED),
    }
}

/// The flag set by the first Ctrl-C or SIGTERM ([`Stop::on_signals`]).
pub fn stop_flag() -> Arc<AtomicBool> {
    Stop::on_signals().shared()
}

/// Prints what was written: the run (or why it stopped, on stderr) and the files.
pub fn print_written(w: &Written, scene: &Scene) {
    match w.summary(scene) {
        Ok(line) => println!("{line}"),
        Err(why) => eprintln!("{why}"),
    }
    print!("{}", w.files());
}

impl RecordCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        // Installed before loading so an early Ctrl-C still ends in readable, incomplete files.
        let stop = stop_flag();
        let limits = self.limits.limits()?;
        let limit = CoverLimit::from_flags(self.cover_tolerance, self.cover_budget);
        let refine = self.refine;
        let first_refine = refine.params(RefineParams::default());
        let mut opts = RecordOptions {
            detail: self.detail,
            force: self.force,
            reproducible: self.reproducible,
            limits,
            stop: Some(stop.clone()),
            wrappers: self.wrapper,
            cover: limit.map(|l| (l, self.cover_kinds)),
            all_levels: self.all_levels,
            mcap_compression: self.mcap_compression,
            // Checked on the defaults first; the fast path's are set once the size is known.
            refine: first_refine,
            live: Live::default(),
        };
        opts.check()?;
        // Started before loading, so that a viewer can connect while the scene loads.
        let live = self.live.start(&stop)?;
        opts.live = live.clone();
        let loaded = self.scene.load()?;
        if refine.refine {
            opts.refine = refine.params(self.group.refinement().params(loaded.scene.len()));
            opts.check()?;
        }
        let params = self.group.params()?.resolve(&loaded.scene);
        let prefix = output_prefix(self.output.as_deref(), &loaded.source.file_name, "")?;
        let progress = Progress::for_merges(loaded.scene.len() as u64);
        let w = record(&loaded, &params, &prefix, &opts, progress)?;
        print_written(&w, &loaded.scene);
        after_run(&live, &stop);
        Ok(exit_code(&w))
    }
}
