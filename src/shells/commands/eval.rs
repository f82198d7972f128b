//! `arlpcg eval`: loads the Generator and the Solvers, runs [`crate::services::eval::evaluate`], writes
//! results.md, the CSV tables, results.json and results.png.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use crate::services::eval::{self, Budget, NamedSolver, PART_FILE, Part};
use crate::services::fsio::{self, Overwrite};
use crate::services::generation::GeneratorPolicy;
use crate::services::panel::Judge;
use crate::services::policies::{GENERATOR_FILE, load_generator, load_solver};
use crate::services::profile;
use crate::services::verify::{Solver, SolverPolicy};
use crate::shells::cli::EvalArgs;
use arlpcg_core::game::Skill;
use arlpcg_core::level::profile::Profile;
use arlpcg_core::rl::checkpoint::{PolicyCard, TrainMode};

pub fn run(args: &EvalArgs) -> Result<()> {
    if !args.merge.is_empty() {
        return merge(args);
    }
    if !args.runs.is_empty() {
        return seeds(args);
    }
    if let Some(missing) = args.policies.iter().find(|dir| !dir.is_dir()) {
        bail!("--policies {}: no such folder", missing.display());
    }
    let generator_path = args
        .policies
        .iter()
        .map(|dir| dir.join(GENERATOR_FILE))
        .find(|p| p.exists())
        .with_context(|| format!("no {GENERATOR_FILE} in any --policies folder"))?;
    let (generator, _) = load_generator(&generator_path, args.game)?;
    let solvers = load_solvers(args)?;
    let profile = asked_profile(args)?;
    // The shipped pair's Solver is named first when the profile lies beyond the Solvers.
    let arlpcg_first = solvers.iter().filter(|(mode, _)| mode == "arlpcg");
    for (_, policy) in arlpcg_first.chain(solvers.iter().filter(|(mode, _)| mode != "arlpcg")) {
        crate::shells::common::check_fit(policy, profile.as_ref())?;
    }
    let budget = budget(args);
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    let pool = crate::shells::common::thread_pool(args.threads)?;
    // The trained Solvers, then the scripted player at each skill: every judge of the panel.
    let named: Vec<NamedSolver> = solvers
        .iter()
        .map(|(mode, policy)| NamedSolver {
            mode: mode.clone(),
            solver: Solver::Policy(policy),
        })
        .chain(Skill::ALL.into_iter().map(|skill| NamedSolver {
            mode: Judge::Scripted(skill).name(),
            solver: Solver::Scripted(skill),
        }))
        .collect();
    if let Some(shard) = args.shard {
        let generated = (&generator, profile.as_ref());
        return write_shard(args, shard, &pool, generated, &named, budget, overwrite);
    }
    let names = [
        "results.md", "results.json", "results.png", "controllability.csv", "generalization.csv",
        "cross.csv",
    ];
    if overwrite == Overwrite::Never {
        for name in names {
            let path = args.out.join(name);
            if path.exists() {
                bail!(
                    "{} exists: add --force to replace the results, or choose another --out",
                    path.display()
                );
            }
        }
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    crate::warn!(
        "generator {}; solvers: {}",
        generator_path.display(),
        named
            .iter()
            .map(|s| s.mode.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let bar = crate::shells::common::progress_bar(
        eval::levels_to_play(budget, named.len(), generator.knobs),
        "levels played",
    );
    let results = pool
        .install(|| eval::evaluate(&generator, &named, budget, profile.as_ref(), &|| bar.inc(1)))?;
    bar.finish_and_clear();
    write_results(&results, &args.out, overwrite)
}

/// The game profile `--profile` names, checked against `--game`.
fn asked_profile(args: &EvalArgs) -> Result<Option<Profile>> {
    args.profile
        .as_ref()
        .map(|file| profile::for_game(profile::load(file)?, args.game, file))
        .transpose()
}

/// The budget the arguments ask for.
fn budget(args: &EvalArgs) -> Budget {
    let base = if args.full {
        Budget::FULL
    } else {
        Budget::QUICK
    };
    Budget {
        tracks: args.tracks.unwrap_or(base.tracks),
        trials: args.trials.unwrap_or(base.trials),
        validation_tracks: args.validation_tracks.unwrap_or(base.validation_tracks),
        validation_trials: args.trials.unwrap_or(base.validation_trials),
    }
}

/// A run of `--runs`: its folder, Solver, Solver's card and Generator (adversarial runs).
type LoadedRun<'a> = (
    &'a PathBuf,
    SolverPolicy,
    PolicyCard,
    Option<GeneratorPolicy>,
);

/// Each `--runs` folder's Solver, card and (adversarial runs) Generator; a run named twice, or
/// copied under another name, is refused (it would count as two seeds).
fn load_runs(args: &EvalArgs) -> Result<Vec<LoadedRun<'_>>> {
    // A run named twice would count as two seeds (and, being its own Generator's, as no other
    // run's on the other Generators' levels).
    for (k, dir) in args.runs.iter().enumerate() {
        let same = |other: &PathBuf| match (dir.canonicalize(), other.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => dir == other,
        };
        if let Some(first) = args.runs[..k].iter().find(|other| same(other)) {
            bail!(
                "--runs names the run {} twice (also as {}): each run is one seed",
                dir.display(),
                first.display()
            );
        }
    }
    let mut loaded: Vec<LoadedRun> = Vec::new();
    for dir in &args.runs {
        let solver_file = dir.join(crate::services::policies::SOLVER_FILE);
        let (solver, card) = load_solver(&solver_file, args.game)?;
        // A seeds table is of the built-in game: a run trained for a profile is not one more
        // seed of it.
        if let Some(profile) = &card.profile {
            bail!(
                "--runs: {} was trained for profile `{}` (its card's profile), not the built-in {} game: a seeds table compares runs of one game; evaluate it with --policies and --profile",
                solver_file.display(),
                profile.name,
                args.game
            );
        }
        let generator_file = dir.join(GENERATOR_FILE);
        let generator = match generator_file.exists() {
            true => Some(load_generator(&generator_file, args.game)?.0),
            false => None,
        };
        // A copied folder is the same run under another name: its Solver's bytes tell.
        if let Some((first, ..)) = loaded
            .iter()
            .find(|(_, other, ..)| other.reference.sha256 == solver.reference.sha256)
        {
            bail!(
                "--runs: {} holds the same Solver as {} (SHA-256 {}): one run counted as two seeds",
                dir.display(),
                first.display(),
                solver.reference.sha256
            );
        }
        loaded.push((dir, solver, card, generator));
    }
    Ok(loaded)
}

/// `eval --runs`: every run's Solver on one validation set, each adversarial run's own pair on
/// its controllability levels, summarized over seeds (seeds.md, seeds.json).
fn seeds(args: &EvalArgs) -> Result<()> {
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    let targets = [args.out.join("seeds.md"), args.out.join("seeds.json")];
    for target in &targets {
        fsio::check_writable(target, overwrite)?;
    }
    let folder = match args.policies.first() {
        Some(folder) => folder.clone(),
        None => crate::shells::common::shipped_dir(args.game)?,
    };
    let (validation_generator, _) = load_generator(&folder.join(GENERATOR_FILE), args.game)?;
    let loaded = load_runs(args)?;
    let runs: Vec<eval::seeds::SeedRun> = loaded
        .iter()
        .map(|(dir, solver, card, generator)| eval::seeds::SeedRun {
            folder: dir.display().to_string(),
            mode: card.training.mode.to_string(),
            seed: card.training.seed,
            solver,
            generator: generator.as_ref(),
        })
        .collect();
    // The outside judges, from the same folder.
    let judges = [
        Judge::Solver(TrainMode::RulePcg),
        Judge::Scripted(Skill::Median),
        Judge::Scripted(Skill::Expert),
    ];
    let available: Vec<Judge> = judges
        .into_iter()
        .filter(|&j| crate::services::policies::judge_file(&folder, j).is_none_or(|p| p.exists()))
        .collect();
    let judges = crate::services::policies::load_panel(&folder, args.game, Some(&available))?;
    let budget = budget(args);
    let pool = crate::shells::common::thread_pool(args.threads)?;
    let validation = pool.install(|| {
        eval::validation_levels(&validation_generator, budget.validation_tracks, None)
    })?;
    let rule_levels = validation.iter().filter(|l| eval::is_rule_level(l)).count();
    let arlpcg_generators = runs
        .iter()
        .filter(|r| r.mode == "arlpcg" && r.generator.is_some())
        .count();
    let per_run = |r: &eval::seeds::SeedRun| {
        let own = r.mode == "arlpcg" && r.generator.is_some();
        validation.len() as u64
            + eval::seeds::other_generators_plays(arlpcg_generators, own, budget.tracks)
            + r.generator.map_or(0, |_| {
                (1 + judges.judges.len() as u64)
                    * eval::AUX_VALUES.len() as u64
                    * budget.tracks as u64
            })
    };
    let bar = crate::shells::common::progress_bar(runs.iter().map(per_run).sum(), "levels played");
    let scores = pool.install(|| {
        eval::seeds::score_runs(&runs, &judges, &validation, rule_levels, budget, &|| {
            bar.inc(1)
        })
    })?;
    bar.finish_and_clear();
    let results = eval::seeds::summarize(budget, &validation_generator.reference.path, scores);
    let markdown = eval::seeds::markdown(&results);
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut batch = fsio::FileBatch::new();
    batch.stage(&targets[0], markdown.as_bytes(), overwrite)?;
    batch.stage(
        &targets[1],
        &serde_json::to_vec_pretty(&results)?,
        overwrite,
    )?;
    batch.commit()?;
    crate::say!("{markdown}");
    crate::say!(
        "wrote {} and {}",
        targets[0].display(),
        targets[1].display()
    );
    Ok(())
}

/// Writes results.md, results.json, results.png and the CSV tables into `out`.
fn write_results(results: &eval::Results, out: &Path, overwrite: Overwrite) -> Result<()> {
    let markdown = eval::markdown(results);
    let mut files: Vec<(String, Vec<u8>)> = vec![
        ("results.md".into(), markdown.clone().into_bytes()),
        ("results.json".into(), serde_json::to_vec_pretty(results)?),
        ("results.png".into(), eval::chart(results).to_png()),
    ];
    for (name, text) in eval::csv_tables(results) {
        files.push((name.into(), text.into_bytes()));
    }
    let mut batch = fsio::FileBatch::new();
    for (name, bytes) in &files {
        batch.stage(&out.join(name), bytes, overwrite)?;
    }
    batch.commit()?;
    crate::say!("{markdown}");
    crate::say!("wrote {} files to {}", files.len(), out.display());
    Ok(())
}

/// `eval --merge`: the tables from the parts of a sharded evaluation.
fn merge(args: &EvalArgs) -> Result<()> {
    let mut parts: Vec<(PathBuf, Part)> = Vec::new();
    for dir in &args.merge {
        let path = dir.join(PART_FILE);
        let bytes = fsio::read_limited(&path, 1 << 30, "eval part")?;
        let part: Part = serde_json::from_slice(&bytes)
            .with_context(|| format!("{}: not an eval part file", path.display()))?;
        parts.push((path, part));
    }
    let results = eval::merge(parts)?;
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    write_results(&results, &args.out, overwrite)
}

/// Every `solver*.safetensors` in the `--policies` folders, named by its card's training mode
/// (the first of each mode wins); the ARLPCG one must be among them.
fn load_solvers(args: &EvalArgs) -> Result<Vec<(String, SolverPolicy)>> {
    let mut solvers: Vec<(String, SolverPolicy)> = Vec::new();
    for dir in &args.policies {
        let entries = std::fs::read_dir(dir)
            .with_context(|| format!("cannot read the policies folder {}", dir.display()))?;
        let mut files: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with("solver") && n.ends_with(".safetensors"))
            })
            .collect();
        files.sort();
        for path in files {
            let (solver, card) = load_solver(&path, args.game)?;
            let name = card.training.mode.to_string();
            if let Some((mode, _)) = solvers.iter().find(|(m, _)| *m == name) {
                crate::warn!(
                    "note: {} skipped: a {mode} Solver is already loaded",
                    path.display()
                );
                continue;
            }
            solvers.push((name, solver));
        }
    }
    if !solvers.iter().any(|(mode, _)| mode == "arlpcg") {
        bail!(
            "no arlpcg Solver (a solver*.safetensors whose card says mode arlpcg) in the --policies folders: it plays the controllability table"
        );
    }
    Ok(solvers)
}

/// `eval --shard I/K`: plays this shard's share of the evaluation and writes its part.
fn write_shard(
    args: &EvalArgs,
    shard: crate::shells::cli::Shard,
    pool: &rayon::ThreadPool,
    (generator, profile): (&GeneratorPolicy, Option<&Profile>),
    named: &[NamedSolver],
    budget: Budget,
    overwrite: Overwrite,
) -> Result<()> {
    // The target is checked before the evaluation, not after it.
    let path = args.out.join(PART_FILE);
    if args.out.exists() && !args.out.is_dir() {
        bail!("--out {} is not a folder", args.out.display());
    }
    fsio::check_writable(&path, overwrite)?;
    let part = pool.install(|| -> Result<Part> {
        let levels = eval::levels(generator, named, budget, profile)?;
        let indices: Vec<usize> = (0..levels.layout.plays().len())
            .filter(|&i| shard.owns(i as u64))
            .collect();
        let bar = crate::shells::common::progress_bar(indices.len() as u64, "levels played");
        let stats = eval::play(&levels, named, budget, &indices, &|| bar.inc(1));
        bar.finish_and_clear();
        Ok(Part::new(
            [shard.index, shard.count],
            budget,
            generator.reference.clone(),
            named
                .iter()
                .map(|s| (s.mode.clone(), s.solver.policy_reference()))
                .collect(),
            (levels.layout, indices.into_iter().zip(stats).collect()),
            profile.map(|p| p.record()),
        ))
    })?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    fsio::write_atomic(&path, &serde_json::to_vec(&part)?, overwrite)?;
    crate::say!(
        "wrote shard {}/{} ({} of the evaluation's plays) to {}",
        shard.index,
        shard.count,
        part.plays.len(),
        path.display()
    );
    Ok(())
}
