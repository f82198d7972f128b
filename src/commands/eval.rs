//! `arlpcg eval`: loads the Generator and the Solvers, runs [`crate::eval::evaluate`], writes
//! results.md, the CSV tables, results.json and results.png.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use anyhow::{Context, Result, bail};

use crate::cli::EvalArgs;
use crate::eval::{self, Budget, Layout, NamedSolver};
use crate::fsio::{self, Overwrite};
use crate::level::PolicyRef;
use crate::level::stats::SolverStats;
use crate::policies::{GENERATOR_FILE, load_generator, load_solver};
use crate::verify::SolverPolicy;

/// The file a shard writes (`--shard`) and `--merge` reads.
const PART_FILE: &str = "eval-part.json";
/// What an eval part file says it is.
const PART_FORMAT: &str = "arlpcg-eval-part";
const PART_VERSION: u32 = 2;

/// One shard's raw results: enough to rebuild the tables with the other shards.
#[derive(Debug, Serialize, Deserialize)]
struct Part {
    format: String,
    version: u32,
    /// The arlpcg version that played it.
    arlpcg: String,
    shard: [u64; 2],
    budget: Budget,
    generator: PolicyRef,
    /// Each Solver's mode and file, in table order.
    solvers: Vec<(String, PolicyRef)>,
    layout: Layout,
    /// (play index, its statistics) for this shard's plays.
    plays: Vec<(usize, SolverStats)>,
}

pub fn run(args: &EvalArgs) -> Result<()> {
    if !args.merge.is_empty() {
        return merge(args);
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
            if let Some((mode, _)) = solvers.iter().find(|(m, _)| *m == card.training.mode) {
                eprintln!(
                    "note: {} skipped: a {mode} Solver is already loaded",
                    path.display()
                );
                continue;
            }
            solvers.push((card.training.mode.clone(), solver));
        }
    }
    if !solvers.iter().any(|(mode, _)| mode == "arlpcg") {
        bail!(
            "no arlpcg Solver (a solver*.safetensors whose card says mode arlpcg) in the --policies folders: it plays the controllability table"
        );
    }
    let base = if args.full {
        Budget::FULL
    } else {
        Budget::QUICK
    };
    let budget = Budget {
        tracks: args.tracks.unwrap_or(base.tracks),
        trials: args.trials.unwrap_or(base.trials),
        validation_tracks: args.validation_tracks.unwrap_or(base.validation_tracks),
        validation_trials: args.trials.unwrap_or(base.validation_trials),
    };
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    let pool = crate::shell::thread_pool(args.threads)?;
    let named: Vec<NamedSolver> = solvers
        .iter()
        .map(|(mode, policy)| NamedSolver {
            mode: mode.clone(),
            policy,
        })
        .collect();
    if let Some(shard) = args.shard {
        let part = pool.install(|| -> Result<Part> {
            let levels = eval::levels(&generator, &named, budget)?;
            let indices: Vec<usize> = (0..levels.layout.plays().len())
                .filter(|&i| shard.owns(i as u64))
                .collect();
            let bar = crate::shell::progress_bar(indices.len() as u64, "levels played");
            let stats = eval::play(&levels, &named, budget, &indices, &|| bar.inc(1));
            bar.finish_and_clear();
            Ok(Part {
                format: PART_FORMAT.into(),
                version: PART_VERSION,
                arlpcg: env!("CARGO_PKG_VERSION").into(),
                shard: [shard.index, shard.count],
                budget,
                generator: generator.reference.clone(),
                solvers: solvers
                    .iter()
                    .map(|(mode, p)| (mode.clone(), p.reference.clone()))
                    .collect(),
                layout: levels.layout,
                plays: indices.into_iter().zip(stats).collect(),
            })
        })?;
        std::fs::create_dir_all(&args.out)
            .with_context(|| format!("cannot create {}", args.out.display()))?;
        let path = args.out.join(PART_FILE);
        fsio::write_atomic(&path, &serde_json::to_vec(&part)?, overwrite)?;
        println!(
            "wrote shard {}/{} ({} of the evaluation's plays) to {}",
            shard.index,
            shard.count,
            part.plays.len(),
            path.display()
        );
        return Ok(());
    }
    let names = [
        "results.md",
        "results.json",
        "results.png",
        "controllability.csv",
        "generalization.csv",
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
    eprintln!(
        "generator {}; solvers: {}",
        generator_path.display(),
        named
            .iter()
            .map(|s| s.mode.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let bar =
        crate::shell::progress_bar(eval::levels_to_play(budget, named.len()), "levels played");
    let results = pool.install(|| eval::evaluate(&generator, &named, budget, &|| bar.inc(1)))?;
    bar.finish_and_clear();
    write_results(&results, &args.out, overwrite)
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
    for (name, bytes) in &files {
        fsio::write_atomic(&out.join(name), bytes, overwrite)?;
    }
    println!("{markdown}");
    println!("wrote {} files to {}", files.len(), out.display());
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
        if part.format != PART_FORMAT || part.version != PART_VERSION {
            bail!(
                "{}: format {} version {}, expected {PART_FORMAT} version {PART_VERSION}",
                path.display(),
                part.format,
                part.version
            );
        }
        parts.push((path, part));
    }
    let (first_path, first) = &parts[0];
    let count = first.shard[1];
    for (path, part) in &parts[1..] {
        let differs = if part.arlpcg != first.arlpcg {
            Some("arlpcg version")
        } else if part.budget != first.budget {
            Some("budget")
        } else if part.generator.sha256 != first.generator.sha256 {
            Some("Generator")
        } else if part.solvers.len() != first.solvers.len()
            || part
                .solvers
                .iter()
                .zip(&first.solvers)
                .any(|(a, b)| a.0 != b.0 || a.1.sha256 != b.1.sha256)
        {
            Some("Solvers")
        } else if part.layout != first.layout {
            Some("levels")
        } else if part.shard[1] != count {
            Some("shard count")
        } else {
            None
        };
        if let Some(what) = differs {
            bail!(
                "{} and {} come from different evaluations: their {what} differ",
                first_path.display(),
                path.display()
            );
        }
    }
    let mut seen = vec![false; count as usize];
    for (path, part) in &parts {
        let index = part.shard[0] as usize;
        if std::mem::replace(&mut seen[index], true) {
            bail!(
                "shard {index}/{count} is given twice (again in {})",
                path.display()
            );
        }
    }
    let missing: Vec<String> = (0..count as usize)
        .filter(|&i| !seen[i])
        .map(|i| i.to_string())
        .collect();
    match missing.len() {
        0 => {}
        1 => bail!(
            "shard {}/{count} is missing: merge needs every --shard I/{count}",
            missing[0]
        ),
        _ => bail!(
            "shards {} (of {count}) are missing: merge needs every --shard I/{count}",
            missing.join(", ")
        ),
    }
    let total = first.layout.plays().len();
    let mut stats: Vec<Option<SolverStats>> = vec![None; total];
    for (path, part) in parts.iter_mut() {
        for (i, s) in std::mem::take(&mut part.plays) {
            if i >= total || i as u64 % count != part.shard[0] {
                bail!("{}: play {i} does not belong to its shard", path.display());
            }
            stats[i] = Some(s);
        }
    }
    let stats: Vec<SolverStats> = stats
        .into_iter()
        .enumerate()
        .map(|(i, s)| s.with_context(|| format!("play {i} is missing from its shard's part")))
        .collect::<Result<_>>()?;
    let first = &parts[0].1;
    let results = eval::assemble(first.budget, &first.generator.path, &first.layout, &stats);
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    write_results(&results, &args.out, overwrite)
}
