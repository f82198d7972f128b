//! The arguments of the commands that make and export levels: `generate`, `export` and
//! `export-policy`.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::values::{
    parse_aux_arg, parse_contract, parse_game, parse_keep, parse_point, parse_shard, parse_target,
};
use super::{AuxArg, KeepArg, Shard};
use crate::services::generation::Ask;
use crate::services::panel::Judge;
use crate::services::wish::{Constraint, Want};
use arlpcg_core::level::Game;
use arlpcg_core::level::pacing::AuxCurve;

/// Output file formats of `generate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    /// The level file (source of truth; `arlpcg export` and `verify` read it).
    Yaml,
    /// glTF 2.0, one binary file.
    Glb,
    /// glTF 2.0 as JSON with a separate .bin buffer.
    Gltf,
}

/// How the glTF files carry their colliders: `generate`, `export`, `campaign` and `design` take
/// the same two options.
#[derive(Debug, Clone, Copy, Default, Args)]
pub struct GltfArgs {
    /// Name every solid node of the glTF with Godot's `-col` import hint, so that Godot 3 (which
    /// ignores the physics extension) makes a static body for each. Not for Godot 4.3 and later,
    /// which read the extension and would make two.
    #[arg(long)]
    pub collision_names: bool,
    /// The glTF physics extensions that carry the colliders and the finish trigger: omi
    /// (`OMI_physics_shape`/`OMI_physics_body`, as Godot 4 reads them), khr (the Khronos drafts
    /// `KHR_implicit_shapes`/`KHR_physics_rigid_bodies`) or both on the same collider nodes.
    #[arg(long, value_enum, value_name = "EXTENSIONS", default_value = "omi")]
    pub physics: PhysicsArg,
}

impl From<GltfArgs> for crate::services::level_files::GltfOptions {
    fn from(args: GltfArgs) -> Self {
        Self {
            collision_names: args.collision_names,
            physics: args.physics.into(),
        }
    }
}

/// The glTF physics extensions (`--physics`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum PhysicsArg {
    /// `OMI_physics_shape` and `OMI_physics_body` (Godot 4.3 and later read them).
    #[default]
    Omi,
    /// The Khronos drafts `KHR_implicit_shapes` and `KHR_physics_rigid_bodies` (three.js with
    /// Rapier, Babylon.js with Havok, the Khronos sample viewer; docs/engines.md).
    Khr,
    /// Both, on the same collider nodes.
    Both,
}

/// `generate`'s arguments.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["rules", "policies"])))]
pub struct GenerateArgs {
    /// Which game (default: the game of --policies or --profile, else platform).
    #[arg(long, default_value = "platform", value_parser = parse_game)]
    pub game: Game,
    /// Use the rule-based generator (random parameters within the game's ranges, kept valid
    /// and within the character's or the car's ability).
    #[arg(long)]
    pub rules: bool,
    /// Racing: place this many obstacles between the start and the goal, which the road (of the
    /// rules or of the Generator) goes around. The racing Generator trained with 3, and its
    /// λ→success curve for --target-success is measured with 3.
    #[arg(long, value_name = "N", default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=200))]
    pub obstacles: u32,
    /// Use the trained Generator in this folder (generator.safetensors; --verify plays the
    /// solver.safetensors beside it). The shipped one: policies/platform.
    #[arg(long, value_name = "DIR")]
    pub policies: Option<PathBuf>,
    /// How many levels; level i uses seed SEED + i.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub count: u32,
    /// Seed of the first level: the same seed gives the same level, byte for byte.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// The aux input λ in [-1, 1]: +1 easy, -1 hard (required with --policies). The rule-based
    /// generator only records it. With a Generator trained with style knobs, named values set
    /// them too, each in [-1, 1] (0, the default: no preference): `difficulty=-0.5,stride=1`
    /// (platform: stride, steps; racing: curviness, elevation).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_aux_arg)]
    pub aux: Option<AuxArg>,
    /// λ along the level instead of one λ (with --policies): control points `fraction:λ`,
    /// where fraction is the share of the start-to-goal distance covered (0 start, 1 goal),
    /// linear between points. "0:1, 0.5:1, 0.6:-1, 1:-1" is easy up to halfway, then hard;
    /// two points at one fraction are a step ("0:1, 0.5:1, 0.5:-1, 1:-1"). Each piece records
    /// the λ it was built at.
    #[arg(long, value_name = "CURVE", allow_hyphen_values = true, value_parser = AuxCurve::parse, conflicts_with_all = ["aux", "target_success"])]
    pub aux_curve: Option<AuxCurve>,
    /// Keep the first K pieces of an existing level (generated or hand-written) and let the
    /// Generator build the rest from there, with --aux or --aux-curve and this run's seed. The
    /// kept pieces are written exactly as they were; the file's `source` names the level kept
    /// from (path and SHA-256) and how many pieces.
    #[arg(long, value_name = "LEVEL.yaml:K", value_parser = parse_keep, requires = "policies", conflicts_with_all = ["goal", "target_success"])]
    pub keep: Option<KeepArg>,
    /// Goal position x,y,z in metres (default: drawn from the seed).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_point)]
    pub goal: Option<[f64; 3]>,
    /// Folder to write into (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// File formats to write, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "yaml,glb")]
    pub format: Vec<FormatArg>,
    /// How the glTF files carry their colliders (`--collision-names`, `--physics`).
    #[command(flatten)]
    pub gltf: GltfArgs,
    /// Play each level this many times with the Solver (with --policies the one beside the
    /// Generator, with --rules the shipped one; under a --profile whose abilities it did not
    /// train with, the scripted expert, who plays with any abilities, and a line says so) and
    /// store the statistics in the YAML.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub verify: Option<u32>,
    /// Play --verify and --target-success with this Solver policy (.safetensors) instead of the
    /// one beside the Generator or the shipped one.
    #[arg(long, value_name = "FILE")]
    pub solver_policy: Option<PathBuf>,
    /// Play --verify and --target-success with this judge instead: a Solver of --policies (or
    /// policies/<game>) named by its training mode (arlpcg, rule-pcg, fixed-track, fixed-aux),
    /// or the scripted player (scripted-novice, scripted-median, scripted-expert).
    #[arg(long, value_name = "NAME", value_parser = Judge::parse, conflicts_with = "solver_policy")]
    pub judge: Option<Judge>,
    /// With --verify, also play each level with the panel of judges (every Solver of --policies
    /// or policies/<game>, and the scripted player at three skills), and record each judge's
    /// success and the level's difficulty b, rated over the levels of this batch.
    #[arg(long, requires = "verify")]
    pub panel: bool,
    /// Replace files that already exist (by default nothing is overwritten; files identical to
    /// what this run makes are left as they are, so a re-run finishes an interrupted batch).
    #[arg(long)]
    pub force: bool,
    /// Ask for a success rate instead of λ (0 < P < 1, with --policies): each level is searched
    /// (λ and draws) until its measured success is within ±0.1 of P; the λ used is recorded.
    /// Verifies with 100 runs unless --verify says otherwise. The policies' λ→success curve is
    /// measured once and kept as difficulty-curve.yaml beside them; a P more than 0.1 beyond
    /// the curve's span is said before the search (only some seeds can meet it).
    #[arg(long, value_name = "P", allow_hyphen_values = true, value_parser = parse_target, conflicts_with = "aux")]
    pub target_success: Option<f64>,
    /// With --verify, keep a level that no run completed. By default it is redrawn (the next
    /// level of the seed, toward the same goal; after 10 such draws, or when the Generator
    /// builds no further valid level toward that goal, its λ is eased by 0.25, each step said,
    /// and the level records the λ it was built at), and each level records one
    /// successful run's seed as its certificate (`verify --replay` re-runs it).
    #[arg(long, requires = "verify")]
    pub allow_unsolved: bool,
    /// Make the levels for this game profile (`arlpcg profile init`): the character's or car's
    /// abilities, which --verify plays with; each level records it. Default: the built-in one.
    #[arg(long, value_name = "FILE")]
    pub profile: Option<PathBuf>,
    /// Search each level until it meets every constraint of this wish list (docs/wish.md):
    /// `"pieces 8..12, climb >= 6, hardest 0.66..1, success 0.4..0.8"`. With --policies, λ
    /// (unless --aux gives it), a curve of λ and the seed's draws are searched; constraints on
    /// runs are played (--verify N runs, else 20). Each level records its want, the draw and
    /// each constraint's measured value; a want no candidate meets is named (exit 1, nothing
    /// written), a contradictory one refused (exit 2).
    #[arg(long, value_name = "WISHES", value_parser = Want::parse, conflicts_with_all = ["target_success", "want_file", "sentence"])]
    pub want: Option<Want>,
    /// The wish list from a file: YAML, `want: "pieces 8..12, climb >= 6"` or a list of
    /// constraints under `want:`.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["target_success", "sentence"])]
    pub want_file: Option<PathBuf>,
    /// The wish list in plain words: "a long, easy level that climbs, with one hard jump near
    /// the end". Read offline by a vocabulary (docs/wish.md), printed as the wish list it
    /// reads as, with every word it did not use named; then searched as --want.
    #[arg(
        long = "ask",
        value_name = "SENTENCE",
        conflicts_with = "target_success"
    )]
    pub sentence: Option<String>,
    /// Acceptance check on every level (repeatable), in the wish-list language (docs/wish.md):
    /// `success LO..HI` (the success ratio), `b LO..HI` (the panel's difficulty, with
    /// --panel), `completed`, or any attribute of the pieces (`pieces 8..12`). A level fails a
    /// success or b range only when its 95% interval lies wholly outside it; any failure ends
    /// the run with exit code 3 and names each level and check (the files are written all the
    /// same).
    #[arg(long = "check", value_name = "CHECK", value_parser = Constraint::parse)]
    pub checks: Vec<Constraint>,
    /// Make only shard I of K of the batch (0 <= I < K): level i of the batch when i mod K = I.
    /// K machines with I = 0..K-1 together write exactly the files of the whole batch.
    #[arg(long, value_name = "I/K", value_parser = parse_shard)]
    pub shard: Option<Shard>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub threads: Option<u64>,
}

/// `bench`'s arguments.
#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    arlpcg bench --game platform --asks results/platform/wish/asks.yaml\n  \
    arlpcg bench --game racing --asks results/racing/wish/asks.yaml --levels 2 --out results/racing/wish/score.json\n\n\
    Quality: the share of levels certified (a recorded run completes them). Controllability: \
    the share meeting every constraint of their ask, and per attribute. Diversity: the mean \
    distance between the levels over pairs (docs/wish.md), beside plain levels of the \
    Generator at λ = 0. A search that meets no candidate counts as a miss for controllability, and is named (its ask, its seed and the closest it came); its closest candidate, played and certified, is its level for quality and diversity.")]
pub struct BenchArgs {
    /// Which game (default: the game of --policies, else platform).
    #[arg(long, default_value = "platform", value_parser = parse_game)]
    pub game: Game,
    /// The ask set: YAML, `asks:` a list, each `want: WISHES` or `ask: SENTENCE` (docs/wish.md).
    #[arg(long, value_name = "FILE")]
    pub asks: PathBuf,
    /// The Generator and Solver (default: the shipped policies/<game>).
    #[arg(long, value_name = "DIR")]
    pub policies: Option<PathBuf>,
    /// Levels searched for each ask, from seeds 0, 1, ...
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub levels: u32,
    /// Runs per played candidate.
    #[arg(long, value_name = "N", default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub trials: u32,
    /// Write the score as JSON here (an existing file is replaced only with --force).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Replace --out if it exists.
    #[arg(long)]
    pub force: bool,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub threads: Option<u64>,
}

/// `export`'s arguments.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The level file (.yaml).
    pub level: PathBuf,
    /// Output file: .glb for binary glTF, .gltf for JSON glTF plus a .bin beside it.
    #[arg(long)]
    pub out: PathBuf,
    /// How the glTF files carry their colliders (`--collision-names`, `--physics`).
    #[command(flatten)]
    pub gltf: GltfArgs,
    /// Replace files that already exist.
    #[arg(long)]
    pub force: bool,
}

/// `view`'s arguments.
#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    arlpcg view levels/platform/platform_seed7_aux-1.00.yaml\n  \
    arlpcg view levels            # the newest level the designer or generate writes there\n  \
    arlpcg view my-levels --port 8080\n  \
    arlpcg view levels/racing/racing_seed7_aux+0.00.yaml --policies runs/my-racing\n\n\
    In the page: drag to orbit, the wheel to zoom, f to look from the start toward the goal; \
    the λ slider (or [ and ]) rebuilds the level's seed, start, goal and obstacles at another λ \
    with the Generator of --policies, unplayed (back at the file's own λ it is the file's level \
    when that was its seed's first draw). \
    Pieces are tinted red by their share of the failures the level's statistics record; the \
    certificate's run (the recorded run that reaches the goal) is drawn in blue, played again \
    with the Solver its statistics name.")]
pub struct ViewArgs {
    /// A level file (.yaml), or a folder: the page shows its newest level file and follows it.
    pub level: PathBuf,
    /// The port to serve on, on 127.0.0.1 (0: any free one; the address is printed).
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// The Generator the page's λ slider rebuilds levels with: a policies folder (its
    /// generator.safetensors) or a Generator's file. Default: the shipped policies/<game>/ of
    /// the level shown ($ARLPCG_POLICIES, else ./policies, else beside the binary).
    #[arg(long, value_name = "PATH")]
    pub policies: Option<PathBuf>,
}

/// `export-policy`'s arguments.
#[derive(Debug, Args)]
#[command(
    after_help = "The graph takes raw observations (the normalizer is inside) and gives \
    the deterministic actions this tool plays with. The sidecar (OUT.json) lists the observation \
    layout, each output's meaning and example rows with their expected outputs.\n\n\
    Examples:\n  \
    arlpcg export-policy policies/racing/solver.safetensors --out racing-solver.onnx\n  \
    arlpcg export-policy policies/platform/solver.safetensors --contract mlagents --out Platform.onnx"
)]
pub struct ExportPolicyArgs {
    /// The policy file (.safetensors): a Solver or a Generator of either game.
    pub policy: PathBuf,
    /// Output file: .onnx, the graph, with its sidecar beside it as OUT.json (and a golden
    /// episode); or, for a Generator, .json: its sidecar with the actor's numbers, for
    /// web/network.mjs, which builds its levels in JavaScript with no ONNX runtime.
    #[arg(long)]
    pub out: PathBuf,
    /// Whose names the graph uses: `plain` (this tool's) or `mlagents` (ML-Agents' model
    /// contract, for Unity's Inference Engine). Also accepted as --profile, its former name.
    #[arg(long, alias = "profile", default_value = "plain", value_parser = parse_contract)]
    pub contract: crate::services::onnx::Contract,
    /// Replace files that already exist.
    #[arg(long)]
    pub force: bool,
}

impl GenerateArgs {
    /// What difficulty is asked for (clap refuses two of `--aux`, `--aux-curve` and
    /// `--target-success` together); none for rule levels that record no λ.
    pub fn ask(&self) -> Option<Ask> {
        let aux = self.aux.as_ref().and_then(|aux| aux.difficulty);
        match (self.target_success, &self.aux_curve, aux) {
            (Some(target), _, _) => Some(Ask::Success(target)),
            (None, Some(curve), _) => Some(Ask::Curve(curve.clone())),
            (None, None, aux) => aux.map(Ask::Aux),
        }
    }
}

impl From<FormatArg> for crate::services::level_files::Format {
    fn from(format: FormatArg) -> Self {
        match format {
            FormatArg::Yaml => Self::Yaml,
            FormatArg::Glb => Self::Glb,
            FormatArg::Gltf => Self::Gltf,
        }
    }
}

impl From<PhysicsArg> for arlpcg_core::level::scene::PhysicsExtensions {
    fn from(physics: PhysicsArg) -> Self {
        match physics {
            PhysicsArg::Omi => Self::Omi,
            PhysicsArg::Khr => Self::Khr,
            PhysicsArg::Both => Self::Both,
        }
    }
}
