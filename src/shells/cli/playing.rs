//! The arguments of the commands that play levels: `verify` (and who plays it) and `campaign`.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::values::{parse_game, parse_judges, parse_population, parse_retry};
use super::{FormatArg, GltfArgs, Judges};
use crate::services::campaign::Ramp;
use crate::services::panel::Judge;
use crate::services::wish::Constraint;
use arlpcg_core::game::Skill;
use arlpcg_core::level::Game;
use arlpcg_core::level::pacing::AuxCurve;

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
    /// scripted player; on a level made for abilities the shipped Solver did not train with, the
    /// scripted expert, and a line says so).
    #[arg(long, value_enum)]
    pub solver: Option<SolverChoice>,
    /// The Solver policy file (.safetensors) for --solver policy (default:
    /// policies/<game>/solver.safetensors for each level's game).
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
    /// Acceptance check on every level (repeatable), in the wish-list language (docs/wish.md):
    /// `success LO..HI` (the success ratio), `b LO..HI` (the panel's difficulty, with
    /// --panel), `completed`, or any attribute of the pieces or runs (`pieces 8..12`,
    /// `hardest 0.6..1`). A level fails a success or b range only when its 95% interval lies
    /// wholly outside it; any failure ends the run with exit code 3 and names each level and
    /// check.
    #[arg(long = "check", value_name = "CHECK", value_parser = Constraint::parse)]
    pub checks: Vec<Constraint>,
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
    /// Which game (default: the game of --policies or --profile, else platform).
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
    /// Acceptance check on every level (repeatable), in the wish-list language (docs/wish.md):
    /// `success LO..HI` (the success ratio), `b LO..HI` (the panel's difficulty),
    /// `completed`, or any attribute of the pieces or runs (`pieces 8..12`). A level fails a
    /// success or b range only when its 95% interval lies wholly outside it; any failure ends
    /// the run with exit code 3 and names each level and check (the files are written all the
    /// same).
    #[arg(long = "check", value_name = "CHECK", value_parser = Constraint::parse)]
    pub checks: Vec<Constraint>,
    /// Level file formats, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "yaml,glb")]
    pub format: Vec<FormatArg>,
    /// How the glTF files carry their colliders (`--collision-names`, `--physics`).
    #[command(flatten)]
    pub gltf: GltfArgs,
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
