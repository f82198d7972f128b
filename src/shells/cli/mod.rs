//! The command line: one argument struct per subcommand (clap derive), with the help a designer
//! reads. Parsing only; [`crate::shells::commands`] runs them. Here the top level, the designer,
//! `report`, `eval` and `train`; `making.rs` holds `generate`'s and the exports', `playing.rs`
//! `verify`'s and `campaign`'s, `values.rs` the parsers of argument values.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

mod game;
mod making;
mod playing;
mod values;
pub use making::{
    BenchArgs, ExportArgs, ExportPolicyArgs, FormatArg, GenerateArgs, GltfArgs, ViewArgs,
};
pub use playing::{CampaignArgs, SolverChoice, VerifyArgs, default_solver};
pub use values::{AuxArg, Judges, KeepArg, Shard};
use values::{parse_ability_spread, parse_game, parse_minutes, parse_shard};

use arlpcg_core::level::Game;
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
    /// Write a trained policy's actor as ONNX (with a JSON sidecar), to run it in an engine; a
    /// Generator also as JSON numbers for a web page (--out G.json).
    ExportPolicy(ExportPolicyArgs),
    /// Show a level in 3D in a web browser: a page served on this machine (127.0.0.1), offline,
    /// that follows the level file, or the newest level of a folder, as it changes.
    View(ViewArgs),
    /// Play levels many times and report how often the Solver gets through.
    Verify(VerifyArgs),
    /// Score wish lists the way the PCG Benchmark does: a set of asks, levels searched for
    /// each, and their quality, controllability, diversity and time per level.
    Bench(BenchArgs),
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
        /// Worker threads (default: all cores).
        #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
        threads: Option<u64>,
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
    /// Which game (default: the game of --policies or --profile, else platform).
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
    /// How the glTF files carry their colliders (`--collision-names`, `--physics`).
    #[command(flatten)]
    pub gltf: GltfArgs,
    /// Threads the designer plays on: its trials, and apart from them its λ sweep and its
    /// panel (default: all cores).
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
    /// Which game (default: the game of --policies or --profile, else platform).
    #[arg(long, default_value = "platform", value_parser = parse_game)]
    pub game: Game,
    /// Folders of trained policies: the Generator (generator.safetensors, from the first folder
    /// that has one) and every Solver (solver*.safetensors; each named by its card's training
    /// mode). One Solver must be the arlpcg one.
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
    /// Train ability-aware agents, in place of the configuration's `ability_spread` and
    /// `ability_ranges`: each episode and match draws jump speed, run speed and gravity (racing:
    /// engine force, grip, steering) within this share of the profile's (0.2: ±20%), and both
    /// agents observe them; 0 trains one character or car.
    /// A resumed run keeps its own.
    #[arg(long, value_name = "SHARE", value_parser = parse_ability_spread)]
    pub ability_spread: Option<f64>,
    /// Print the configuration a new run with these --game, --mode and --config would train
    /// with (the defaults, or the file laid over them) as YAML, and exit.
    #[arg(long)]
    pub print_config: bool,
    /// Worker threads for environments and networks (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub threads: Option<u64>,
}

#[cfg(test)]
mod tests {
    use super::values::{parse_aux, parse_aux_arg, parse_point};
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

    #[test]
    fn aux_takes_a_number_or_named_knobs() {
        let aux = |d: Option<f64>, knobs: &[(&str, f64)]| AuxArg {
            difficulty: d,
            knobs: knobs.iter().map(|(n, v)| (n.to_string(), *v)).collect(),
        };
        assert_eq!(parse_aux_arg("-0.5"), Ok(aux(Some(-0.5), &[])));
        assert_eq!(
            parse_aux_arg("difficulty=-0.5, stride=1"),
            Ok(aux(Some(-0.5), &[("stride", 1.0)]))
        );
        assert_eq!(parse_aux_arg("steps=0"), Ok(aux(None, &[("steps", 0.0)])));
        assert!(parse_aux_arg("stride=2").unwrap_err().contains("stride"));
        assert!(
            parse_aux_arg("stride=1,5")
                .unwrap_err()
                .contains("name=value")
        );
        assert!(parse_aux_arg("=1").unwrap_err().contains("without a name"));
        assert!(
            parse_aux_arg("difficulty=1,difficulty=0")
                .unwrap_err()
                .contains("twice")
        );
    }
}
