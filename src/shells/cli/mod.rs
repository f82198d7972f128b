//! The command line: one argument struct per subcommand (clap derive), with the help a designer
//! reads. Parsing only; [`crate::shells::commands`] runs them.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

mod values;
pub use values::{Judges, KeepArg, Shard};
use values::{
    parse_ability_spread, parse_aux, parse_contract, parse_game, parse_judges, parse_keep,
    parse_minutes, parse_point, parse_population, parse_retry, parse_shard, parse_target,
};

use crate::services::campaign::Ramp;
use crate::services::checks::Check;
use crate::services::generation::Ask;
use crate::services::panel::Judge;
use arlpcg_core::game::Skill;
use arlpcg_core::level::Game;
use arlpcg_core::level::pacing::AuxCurve;
use arlpcg_core::rl::checkpoint::TrainMode;

/// The command line.
#[derive(Debug, Parser)]
#[command(
    name = "arlpcg",
    version,
    about = "Generate 3D game levels with a difficulty knob, prove them playable, export them.",
    long_about = "arlpcg generates levels for two 3D games, a platform game (blocks to jump \
        across) and a racing game (a banked road to drive, around obstacles), checks each one by \
        playing it many times, and exports it as YAML (the source of truth) and glTF (for \
        Blender, Godot, Unity).\n\n\
        Levels come from a Generator trained against a Solver (ARLPCG, EA SEED 2021) and \
        steered by one knob, the aux input λ (+1 easy, -1 hard), or from rule-based generation.",
    after_help = "Examples:\n  \
        arlpcg                      (the designer, on the shipped policies)\n  \
        arlpcg design --policies runs/my-arlpcg --out levels/mine\n  \
        arlpcg generate --policies policies/platform --aux -0.5 --verify 100 --out levels/mine\n  \
        arlpcg generate --game platform --rules --count 20 --seed 1 --out levels/mine\n  \
        arlpcg generate --game racing --rules --obstacles 3 --count 20 --out tracks\n  \
        arlpcg verify levels/mine/*.yaml --trials 100\n  \
        arlpcg export levels/mine/platform_seed1.yaml --out level.glb\n\n\
        The shipped policies (policies/<game>, what commands use without --policies) are found \
        in $ARLPCG_POLICIES (a folder holding platform/ and racing/) when it is set, else in \
        policies/ of the working folder, else in policies/ beside the binary or one or two \
        folders above it (target/release/arlpcg finds its checkout's)."
)]
pub struct Cli {
    /// The subcommand (none: the designer in a terminal, else this help).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Open the designer (the default without a subcommand): steer λ, generate, watch the
    /// Solver's statistics, export. Keys: ? in the designer.
    Design(DesignArgs),
    /// Generate levels and write them as YAML and glTF files.
    Generate(GenerateArgs),
    /// Convert a level file to glTF (.glb, or .gltf with a .bin beside it).
    Export(ExportArgs),
    /// Write a trained policy's actor as ONNX (with a JSON sidecar), to run it in an engine.
    ExportPolicy(ExportPolicyArgs),
    /// Play levels many times and report how often the Solver gets through.
    Verify(VerifyArgs),
    /// Generate a sequence of levels on a difficulty ramp, rate them with the panel of judges,
    /// and report the players it keeps and loses (campaign.yaml, campaign.md, campaign.png).
    Campaign(CampaignArgs),
    /// Reproduce the paper's tables (controllability, generalization, each Solver at each λ)
    /// for trained policies: markdown, CSV, a PNG chart and results.json.
    Eval(EvalArgs),
    /// Train a Solver, alone or against a Generator, with PPO (checkpointed, resumable,
    /// stoppable with Ctrl-C).
    Train(TrainArgs),
    /// Write docs/results.md from the committed results (results/<game>/*.json) and the
    /// shipped policies' cards, or check that it is current; draw runs' learning curves.
    Report(ReportArgs),
    /// Game profiles: the abilities of your character or car as a file (`profile init` prints
    /// ours to edit, `profile check` measures what yours allows); commands take it with
    /// --profile FILE.
    #[command(subcommand)]
    Profile(ProfileCommand),
}

/// `profile`'s subcommands.
#[derive(Debug, Subcommand)]
#[command(after_help = "Examples:\n  \
    arlpcg profile init --game platform > hero.yaml\n  \
    arlpcg profile check hero.yaml\n  \
    arlpcg generate --rules --profile hero.yaml --verify 100 --out hero-levels\n  \
    arlpcg verify levels/hand/staircase.yaml --solver scripted --profile hero.yaml")]
pub enum ProfileCommand {
    /// Print a game's built-in profile (standard output), a comment per field with its range.
    Init {
        /// Which game.
        #[arg(long, default_value = "platform", value_parser = parse_game)]
        game: Game,
    },
    /// Check a profile file and measure what it allows with the scripted expert playing: the
    /// jump and reach table (platform), speed and grip (racing), and how many rule levels it
    /// completes. Exit 1 when the file is wrong or the expert completes under half the levels.
    Check {
        /// The profile file (.yaml).
        file: PathBuf,
        /// Runs per rule level.
        #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=10_000))]
        trials: u32,
    },
}

/// `report`'s arguments.
#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    arlpcg report                      # writes docs/results.md\n  \
    arlpcg report --check              # exit 1 if docs/results.md is not what it would write\n  \
    arlpcg report --curves runs/platform-rule-pcg-s0 runs/racing-rule-pcg-s0")]
pub struct ReportArgs {
    /// The results folder: each game's results.json and seeds.json, and further seeds tables
    /// in its subfolders (results/<game>/NAME/seeds.json).
    #[arg(long, default_value = "results")]
    pub results: PathBuf,
    /// The shipped policies, whose cards the page quotes.
    #[arg(long, default_value = "policies")]
    pub policies: PathBuf,
    /// The page to write.
    #[arg(long, default_value = "docs/results.md")]
    pub out: PathBuf,
    /// Write nothing; exit 1 (naming the first line that differs) when the page is not what
    /// this command would write.
    #[arg(long, conflicts_with = "curves")]
    pub check: bool,
    /// Instead of the page: draw learning-curve.png in each of these run folders from its
    /// metrics (curves are not kept in git).
    #[arg(long, num_args = 1..)]
    pub curves: Vec<PathBuf>,
}

/// `design`'s arguments.
#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    arlpcg design\n  \
    arlpcg design --policies runs/my-arlpcg --out levels/mine --seed 7")]
pub struct DesignArgs {
    /// Which game.
    #[arg(long, default_value = "platform", value_parser = parse_game)]
    pub game: Game,
    /// A policies folder (generator.safetensors and/or solver.safetensors) or one policy file.
    /// Default: the shipped policies/<game>/ ($ARLPCG_POLICIES, else ./policies, else beside the
    /// binary: `arlpcg --help`); without them, rule levels and the scripted controller.
    #[arg(long, value_name = "PATH")]
    pub policies: Option<PathBuf>,
    /// Where exports go (into a folder per game).
    #[arg(long, default_value = "levels", value_name = "DIR")]
    pub out: PathBuf,
    /// The seed of the first level.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Open on the campaign view of this folder (what `arlpcg campaign` wrote; its game).
    #[arg(long, value_name = "DIR")]
    pub campaign: Option<PathBuf>,
    /// Make the levels of --game for this game profile (`arlpcg profile init`): they are
    /// generated and played with its character's or car's abilities, and the header names it.
    #[arg(long, value_name = "FILE")]
    pub profile: Option<PathBuf>,
    /// Worker threads for the trials the designer plays (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub threads: Option<u64>,
}

/// `eval`'s arguments.
#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    arlpcg eval --policies policies/platform --out results/platform\n  \
    arlpcg eval --policies runs/my-arlpcg runs/my-rule-pcg --full --out results/full\n  \
    arlpcg eval --policies policies/platform --shard 0/3 --out parts/0   (and 1/3, 2/3 elsewhere)\n  \
    arlpcg eval --merge parts/0 parts/1 parts/2 --out results/platform")]
pub struct EvalArgs {
    /// Which game.
    #[arg(long, default_value = "platform", value_parser = parse_game)]
    pub game: Game,
    /// Folders of trained policies: the Generator (generator.safetensors, from the first folder
    /// that has one) and every Solver (solver*.safetensors; each named by its card's training
    /// mode, solver-aware.safetensors as `arlpcg-aware`). One Solver must be the arlpcg one.
    #[arg(long, num_args = 1.., required_unless_present_any = ["merge", "runs"], value_name = "DIR")]
    pub policies: Vec<PathBuf>,
    /// Score training runs over their seeds instead: each folder is one run (its
    /// solver.safetensors, and generator.safetensors for adversarial runs; mode and seed from
    /// the card). Writes seeds.md and seeds.json to --out: per mode the IQM and mean validation
    /// success over seeds with 95% stratified-bootstrap intervals, each adversarial run's own
    /// controllability and that of the outside judges (the rule-pcg Solver of the first
    /// --policies folder, the scripted median and expert; the recipe's finish plays the median
    /// in both games), and P(arlpcg > baseline).
    /// The validation set's Generator levels come from the first --policies folder (default
    /// policies/<game>). With two ARLPCG runs or more, every Solver also plays the λ = -1
    /// levels of each ARLPCG run's Generator but its own, with P(arlpcg > baseline) there.
    #[arg(long, num_args = 1.., value_name = "RUN", conflicts_with_all = ["merge", "shard"])]
    pub runs: Vec<PathBuf>,
    /// Play only shard I of K of the evaluation (0 <= I < K) and write its raw per-level
    /// statistics to --out as eval-part.json, for `--merge`.
    #[arg(long, value_name = "I/K", value_parser = parse_shard, conflicts_with = "merge")]
    pub shard: Option<Shard>,
    /// Combine the parts written by `--shard 0/K` ... `--shard K-1/K` (their --out folders)
    /// into the same tables, CSVs, results.json and chart as one unsharded run.
    #[arg(long, num_args = 1.., value_name = "DIR", conflicts_with_all = ["policies", "full", "tracks", "trials", "validation_tracks"])]
    pub merge: Vec<PathBuf>,
    /// Generator levels per λ (default 20; 50 with --full).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub tracks: Option<u32>,
    /// Solver runs per level (default 20; 1000 with --full).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub trials: Option<u32>,
    /// Validation levels for the generalization table (default 40; 1000 with --full).
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    pub validation_tracks: Option<u32>,
    /// The paper's scale (hours on 2 cores) instead of a few minutes.
    #[arg(long)]
    pub full: bool,
    /// Folder for results.md, the CSV tables, results.png and results.json.
    #[arg(long, default_value = "results/platform")]
    pub out: PathBuf,
    /// Replace result files that already exist.
    #[arg(long)]
    pub force: bool,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub threads: Option<u64>,
    /// Make and play every level for this game profile (`arlpcg profile init`); results.json
    /// records it (a shard's part too, which --merge then keeps). Not with --runs, whose seeds
    /// tables are of the built-in game.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["merge", "runs"])]
    pub profile: Option<PathBuf>,
}

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

/// `generate`'s arguments.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["rules", "policies"])))]
pub struct GenerateArgs {
    /// Which game.
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
    /// generator only records it.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_aux)]
    pub aux: Option<f64>,
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
    /// Name every solid node of the glTF with Godot's `-col` import hint, so that Godot 3 (which
    /// ignores the physics extension) makes a static body for each. Not for Godot 4.3 and later,
    /// which read the extension and would make two.
    #[arg(long)]
    pub collision_names: bool,
    /// Play each level this many times with the Solver (with --policies the one beside the
    /// Generator, with --rules the shipped one; under a --profile whose abilities it did not
    /// train with, the folder's solver-aware.safetensors where its range holds them, else the
    /// scripted expert, who plays with any abilities, and a line says so) and store the
    /// statistics in the YAML.
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
    /// measured once and kept as difficulty-curve.yaml beside them.
    #[arg(long, value_name = "P", allow_hyphen_values = true, value_parser = parse_target, conflicts_with = "aux")]
    pub target_success: Option<f64>,
    /// With --verify, keep a level that no run completed. By default it is redrawn (the next
    /// level of the seed, toward the same goal; after 10 such draws a Generator's λ is eased by
    /// 0.25, and the level records the λ it was built at), and each level records one
    /// successful run's seed as its certificate (`verify --replay` re-runs it).
    #[arg(long, requires = "verify")]
    pub allow_unsolved: bool,
    /// Make the levels for this game profile (`arlpcg profile init`): the character's or car's
    /// abilities, which --verify plays with; each level records it. Default: the built-in one.
    #[arg(long, value_name = "FILE")]
    pub profile: Option<PathBuf>,
    /// Acceptance check on every level (repeatable): `success LO..HI` (the success ratio),
    /// `b LO..HI` (the panel's difficulty, with --panel) or `completed`. A level fails a range
    /// only when its 95% interval lies wholly outside it; any failure ends the run with exit
    /// code 3 and names each level and check (the files are written all the same).
    #[arg(long = "check", value_name = "CHECK", value_parser = Check::parse)]
    pub checks: Vec<Check>,
    /// Make only shard I of K of the batch (0 <= I < K): level i of the batch when i mod K = I.
    /// K machines with I = 0..K-1 together write exactly the files of the whole batch.
    #[arg(long, value_name = "I/K", value_parser = parse_shard)]
    pub shard: Option<Shard>,
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
    /// Name every solid node of the glTF with Godot's `-col` import hint, so that Godot 3 (which
    /// ignores the physics extension) makes a static body for each. Not for Godot 4.3 and later,
    /// which read the extension and would make two.
    #[arg(long)]
    pub collision_names: bool,
    /// Replace files that already exist.
    #[arg(long)]
    pub force: bool,
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
    /// Output file (.onnx); the sidecar goes beside it as OUT.json.
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
        match (self.target_success, &self.aux_curve, self.aux) {
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

/// How a Solver is trained (`train --mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TrainModeArg {
    /// On a fresh rule-based level every episode (the Rule-PCG baseline).
    RulePcg,
    /// On a small fixed set of rule-based levels (the Fixed-Track baseline).
    FixedTrack,
    /// Against a Generator that always has λ = 1 (the ablation).
    FixedAux,
    /// Against a Generator with λ drawn per match (the full method).
    Arlpcg,
}

impl From<TrainModeArg> for TrainMode {
    fn from(mode: TrainModeArg) -> Self {
        match mode {
            TrainModeArg::RulePcg => Self::RulePcg,
            TrainModeArg::FixedTrack => Self::FixedTrack,
            TrainModeArg::FixedAux => Self::FixedAux,
            TrainModeArg::Arlpcg => Self::Arlpcg,
        }
    }
}

/// Who plays the verification trials.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SolverChoice {
    /// A trained Solver policy (--policy, default policies/<game>/solver.safetensors).
    Policy,
    /// The scripted player (no learning) at its best. Platform: faces the next block, runs,
    /// jumps at the edge. Racing: pure pursuit of the centre line at the speed the road ahead
    /// allows.
    #[value(name = "scripted-expert", alias = "scripted")]
    ScriptedExpert,
    /// The scripted player with an average player's mistakes (take-off timing and run-up speed;
    /// grip misjudged, steering wobble).
    ScriptedMedian,
    /// The scripted player with a beginner's mistakes.
    ScriptedNovice,
    /// Uniformly random actions (a baseline).
    Random,
}

impl SolverChoice {
    /// The scripted player's skill, for the scripted choices.
    pub fn skill(self) -> Option<Skill> {
        match self {
            SolverChoice::ScriptedExpert => Some(Skill::Expert),
            SolverChoice::ScriptedMedian => Some(Skill::Median),
            SolverChoice::ScriptedNovice => Some(Skill::Novice),
            SolverChoice::Policy | SolverChoice::Random => None,
        }
    }
}

/// Where the shipped Solver of `game` lives (an error names the places looked at for the
/// shipped policies: [`crate::shells::common::policies_root`]).
pub fn default_solver(game: Game) -> anyhow::Result<PathBuf> {
    Ok(crate::shells::common::shipped_dir(game)?.join(crate::services::policies::SOLVER_FILE))
}

/// `verify`'s arguments.
#[derive(Debug, Args)]
pub struct VerifyArgs {
    /// Level files (.yaml).
    #[arg(required_unless_present = "campaign")]
    pub levels: Vec<PathBuf>,
    /// Runs per level.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub trials: u32,
    /// Seed of the first run; run i uses SEED + i.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Who plays (default: the trained Solver of the level's game when one is found, else the
    /// scripted player; on a level made for abilities no shipped Solver trained with, the
    /// scripted expert, and a line says so).
    #[arg(long, value_enum)]
    pub solver: Option<SolverChoice>,
    /// The Solver policy file (.safetensors) for --solver policy (default:
    /// policies/<game>/solver.safetensors for each level's game, and on a level made for
    /// abilities it did not train with policies/<game>/solver-aware.safetensors where that
    /// file's range holds them).
    #[arg(long)]
    pub policy: Option<PathBuf>,
    /// Print one JSON object per level instead of text.
    #[arg(long)]
    pub json: bool,
    /// Draw the level's difficulty along the way as a PNG: the share of runs that get past
    /// each piece, and the difficulty its λ asked for (one level only).
    #[arg(long, value_name = "FILE.png", conflicts_with = "replay")]
    pub chart: Option<PathBuf>,
    /// Instead of new trials, re-run each level's certificate (the successful run its
    /// statistics record) with the Solver that recorded it, and check that it succeeds again.
    #[arg(long, conflicts_with_all = ["solver", "policy", "trials", "json"])]
    pub replay: bool,
    /// Play each level with a panel of judges (comma-separated; alone: every Solver in
    /// --policies and the scripted player at three skills) and rate its difficulty b over
    /// judges × levels: P(judge succeeds) = σ(θ_judge − b). Judges: arlpcg, rule-pcg,
    /// fixed-track, fixed-aux, scripted-novice, scripted-median, scripted-expert.
    #[arg(long, value_name = "JUDGES", num_args = 0..=1, default_missing_value = "",
          value_parser = parse_judges, conflicts_with_all = ["solver", "policy", "replay", "chart"])]
    pub panel: Option<Judges>,
    /// The policies folder the panel's Solvers (and a campaign's judge) come from (default: the
    /// shipped policies/<game>: $ARLPCG_POLICIES, else ./policies, else beside the binary).
    #[arg(long)]
    pub policies: Option<PathBuf>,
    /// Play under this game profile (`arlpcg profile init`): the character's or car's abilities.
    /// Default: the profile each level records, else the built-in one.
    #[arg(long, value_name = "FILE")]
    pub profile: Option<PathBuf>,
    /// Acceptance check on every level (repeatable): `success LO..HI` (the success ratio),
    /// `b LO..HI` (the panel's difficulty, with --panel) or `completed`. A level fails a range
    /// only when its 95% interval lies wholly outside it; any failure ends the run with exit
    /// code 3 and names each level and check .
    #[arg(long = "check", value_name = "CHECK", value_parser = Check::parse)]
    pub checks: Vec<Check>,
    /// Re-play and re-report a campaign (its campaign.yaml, e.g. after editing its levels or
    /// checks): the judge and the panel play every level again, the population goes through,
    /// the report goes to standard output and its checks (and --check) are applied. Writes
    /// nothing.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["solver", "policy", "replay", "chart", "panel", "json", "levels"])]
    pub campaign: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub threads: Option<u64>,
}

/// `campaign`'s arguments.
#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    arlpcg campaign --game platform --levels 10 --ramp \"0:0.95, 1:0.5\" --judge scripted-median --out campaigns/first\n  \
    arlpcg campaign --game racing --levels 8 --ramp \"0:0.9, 0.5:0.9, 0.5:0.6, 1:0.6\" --check \"success 0.4..1\" --out campaigns/racing\n  \
    arlpcg campaign --game platform --levels 10 --ramp \"0:0.95, 1:0.5\" --out campaigns/first --resume\n  \
    arlpcg verify --campaign campaigns/first/campaign.yaml --check \"b -3..3\"\n\n\
    Exit codes: 0 done, 1 an error (a file, a policy), 2 arguments that do not fit, 3 a level \
    failed a --check (the files are written), 130 interrupted (--resume finishes).")]
pub struct CampaignArgs {
    /// Which game.
    #[arg(long, default_value = "platform", value_parser = parse_game)]
    pub game: Game,
    /// The Generator, the judge and the panel's Solvers (default: the shipped policies/<game>:
    /// $ARLPCG_POLICIES, else ./policies, else beside the binary; `arlpcg --help`).
    #[arg(long, value_name = "DIR")]
    pub policies: Option<PathBuf>,
    /// How many levels.
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..=crate::services::campaign::MOST_LEVELS as i64))]
    pub levels: u32,
    /// The success asked for along the campaign: control points `position:success`, position 0
    /// the first level and 1 the last, linear between them ("0:0.95, 1:0.5"; two points at one
    /// position are a step). Each level is searched (λ and draws) until the judge's success is
    /// within ±0.1 of its point; then neighbours trade places where both still fit, so that
    /// the panel's difficulty b rises along the campaign.
    #[arg(long, value_name = "CURVE", value_parser = Ramp::parse)]
    pub ramp: Ramp,
    /// The shape of λ along every level, an aux curve of `fraction:λ` points ("0:1, 1:-1": easy,
    /// then hard). Each level's search moves the whole curve up or down (its mean is the λ
    /// searched) until the judge's success fits the ramp. Default: one λ per level.
    #[arg(long, value_name = "CURVE", allow_hyphen_values = true, value_parser = AuxCurve::parse)]
    pub pacing: Option<AuxCurve>,
    /// Make every level for this game profile (`arlpcg profile init`); campaign.yaml and each
    /// level record it. Default: the built-in one.
    #[arg(long, value_name = "FILE")]
    pub profile: Option<PathBuf>,
    /// Whose success the ramp asks for: a Solver of --policies named by its training mode
    /// (arlpcg, rule-pcg, fixed-track, fixed-aux) or the scripted player (scripted-novice,
    /// scripted-median, scripted-expert). Default: arlpcg, or scripted-expert under a --profile
    /// whose abilities the folder's Solvers never trained with (a line says so).
    #[arg(long, value_name = "NAME", value_parser = Judge::parse)]
    pub judge: Option<Judge>,
    /// Runs per level, for the judge's search and for each judge of the panel.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u32).range(crate::services::campaign::TRIALS.0 as i64..=crate::services::campaign::TRIALS.1 as i64))]
    pub trials: u32,
    /// Level k is searched from seed SEED + k: the same seed gives the same campaign, byte for
    /// byte.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// The players' ability θ ~ Normal(MEAN, SD) on the panel's logit scale. Default: fitted
    /// so that the scripted novice, median and expert are its 10th, 50th and 90th percentiles.
    #[arg(long, value_name = "MEAN,SD", allow_hyphen_values = true, value_parser = parse_population)]
    pub population: Option<(f64, f64)>,
    /// The chance that a player tries a level again after failing it (else quits).
    #[arg(long, value_name = "P", default_value_t = arlpcg_core::statistics::population::DEFAULT_RETRY, value_parser = parse_retry)]
    pub retry: f64,
    /// Acceptance check on every level (repeatable): `success LO..HI` (the success ratio),
    /// `b LO..HI` (the panel's difficulty) or `completed`. A level fails a range
    /// only when its 95% interval lies wholly outside it; any failure ends the run with exit
    /// code 3 and names each level and check (the files are written all the same).
    #[arg(long = "check", value_name = "CHECK", value_parser = Check::parse)]
    pub checks: Vec<Check>,
    /// Level file formats, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "yaml,glb")]
    pub format: Vec<FormatArg>,
    /// Folder to write into (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Finish an interrupted campaign in --out: its level files are kept and the rest made. The
    /// same arguments: a level searched for another --ramp or verified with other --trials is
    /// refused.
    #[arg(long)]
    pub resume: bool,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub threads: Option<u64>,
}

/// `train`'s arguments.
#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    arlpcg train --game platform --mode arlpcg --seed 1 --out runs/platform-arlpcg-s1\n  \
    arlpcg train --out runs/platform-arlpcg-s1 --resume\n  \
    arlpcg train --game racing --mode rule-pcg --minutes 60 --out runs/racing-solver\n  \
    arlpcg train --game platform --mode arlpcg --steps 200000 --out runs/try\n  \
    arlpcg train --out runs/arlpcg --resume --config new.yaml\n  \
    arlpcg train --print-config > train.yaml")]
pub struct TrainArgs {
    /// Which game (default: platform; a resumed run's own).
    #[arg(long, value_parser = parse_game)]
    pub game: Option<Game>,
    /// How the Solver is trained: on rule levels, on a fixed set, or against a Generator
    /// (`arlpcg`: λ drawn per match; `fixed-aux`: λ = 1). The adversarial modes train and save
    /// the Generator too. Default: rule-pcg; a resumed run's own.
    #[arg(long, value_enum)]
    pub mode: Option<TrainModeArg>,
    /// The run's budget: stop when the Solver has learned from this many environment steps in
    /// all, over every resume (default: the configuration's `steps`, the game's recipe: platform
    /// 8M, racing 5M); an adversarial run then plays its `generator.finish`. Given with
    /// --resume it becomes the run's new budget.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub steps: Option<u64>,
    /// Stop this session after this many minutes (its checkpoint is saved; --resume goes on).
    #[arg(long, value_parser = parse_minutes)]
    pub minutes: Option<f64>,
    /// Stop this session once the Solver has learned from this many steps in all (its
    /// checkpoint is saved; --resume goes on with the episodes and matches under way, to the
    /// same bytes as a run never stopped).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub pause_at: Option<u64>,
    /// Training configuration (YAML; see --print-config for every field and its default). With
    /// --resume it replaces the run's hyper-parameters from the checkpoint on (not `seed`,
    /// `hidden`, `solver.num_envs`, `generator.max_pieces` or `generator.curve_offset`); the old
    /// file is kept as config-until-step-N.yaml.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Folder of the run: config, checkpoint, metrics.csv, the trained policy and its card.
    #[arg(long, required_unless_present = "print_config")]
    pub out: Option<PathBuf>,
    /// Continue the run in --out from its checkpoint.
    #[arg(long)]
    pub resume: bool,
    /// The run's seed (network initialization, action sampling, minibatches), in place of the
    /// configuration's `seed` (default 0); the card records it. A resumed run keeps its own:
    /// given with --resume, it must be that seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Train for this game profile (`arlpcg profile init`): the Solver plays with its
    /// character's or car's abilities, on levels made for them; the configuration and the cards
    /// record it. A resumed run keeps its own.
    #[arg(long, value_name = "FILE")]
    pub profile: Option<PathBuf>,
    /// Train ability-aware agents, in place of the configuration's `ability_spread`: each
    /// episode and match draws jump speed, run speed and gravity (racing: engine force, grip,
    /// steering) within this share of the profile's (0.2: ±20%), and both agents observe them.
    /// A resumed run keeps its own.
    #[arg(long, value_name = "SHARE", value_parser = parse_ability_spread)]
    pub ability_spread: Option<f64>,
    /// Print the default configuration as YAML and exit.
    #[arg(long)]
    pub print_config: bool,
    /// Worker threads for environments and networks (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub threads: Option<u64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cli_definition_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }

    #[test]
    fn aux_and_goal_are_checked() {
        assert_eq!(parse_aux("-0.5"), Ok(-0.5));
        assert!(parse_aux("2").unwrap_err().contains("out of range"));
        assert!(parse_aux("NaN").unwrap_err().contains("NaN"));
        assert_eq!(parse_point("1,-2, 3.5"), Ok([1.0, -2.0, 3.5]));
        assert!(parse_point("1,2").is_err());
    }
}
