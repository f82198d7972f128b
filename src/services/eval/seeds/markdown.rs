//! The report of `eval --runs` as markdown (seeds.md).

use super::{DROP_TOLERANCE, Improvement, RunScores, SeedResults, SeedsEstimate};
use arlpcg_core::statistics::over_seeds::Estimate;

/// Each ARLPCG Generator's λ = -1 levels: its own Solver's success (its controllability at
/// λ = -1, the same levels and runs) beside the mean of the other ARLPCG Solvers and of each
/// baseline's Solvers on them.
fn generator_by_generator(results: &SeedResults) -> String {
    let runs: Vec<&RunScores> = results.seeds.values().flatten().collect();
    let baselines: Vec<&str> = results
        .modes
        .iter()
        .map(|m| m.mode.as_str())
        .filter(|m| *m != "arlpcg")
        .collect();
    let mut md = String::from("\n| Generator (λ = -1) | own Solver | other arlpcg Solvers |");
    for b in &baselines {
        md += &format!(" {b} Solvers |");
    }
    md += "\n|---|---|---|";
    md += &"---|".repeat(baselines.len());
    md += "\n";
    let on = |generator: &str, mode: &str| -> String {
        let scores: Vec<f64> = runs
            .iter()
            .filter(|r| r.mode == mode)
            .flat_map(|r| &r.on_other_generators)
            .filter(|g| g.generator == generator)
            .map(|g| g.success_ratio)
            .collect();
        match scores.is_empty() {
            true => String::from("—"),
            false => format!("{:.3}", scores.iter().sum::<f64>() / scores.len() as f64),
        }
    };
    for run in runs.iter().filter(|r| r.mode == "arlpcg") {
        let own = run
            .controllability
            .as_ref()
            .and_then(|c| *c.last()?)
            .map_or(String::from("—"), |x| format!("{x:.3}"));
        md += &format!("| {} | {own} | {} |", run.run, on(&run.run, "arlpcg"));
        for b in &baselines {
            md += &format!(" {} |", on(&run.run, b));
        }
        md += "\n";
    }
    md
}

/// The end of a table's header after its first `leading` columns: one column per λ, then the
/// separator row.
fn aux_columns(aux: &[f64], leading: usize) -> String {
    let mut md = String::new();
    for a in aux {
        md += &format!(" λ = {a:+.1} |");
    }
    md += "\n|";
    md += &"---|".repeat(leading + aux.len());
    md += "\n";
    md
}

/// A P(arlpcg > baseline) table's rows.
fn improvement_rows(beats: &[Improvement], e: impl Fn(&Estimate) -> String) -> String {
    beats
        .iter()
        .map(|b| format!("| {} | {} |\n", b.baseline, e(&b.probability)))
        .collect()
}

/// An estimate with its interval, as every table here prints it.
fn estimate(x: &Estimate) -> String {
    format!("{:.3} [{:.3}, {:.3}]", x.value, x.ci95[0], x.ci95[1])
}

/// An estimate over some of a mode's seeds: how many when not all, "—" where no seed's
/// Generator built a level.
fn seeds_estimate(x: &Option<SeedsEstimate>) -> String {
    match x {
        None => String::from("— (no level built)"),
        Some(SeedsEstimate {
            estimate: e,
            seeds: None,
        }) => estimate(e),
        Some(SeedsEstimate {
            estimate: e,
            seeds: Some(n),
        }) => format!("{} (seeds that built levels: {n})", estimate(e)),
    }
}

/// The report as markdown: every section below, in order.
pub fn markdown(results: &SeedResults) -> String {
    let mut md = validation(results);
    if !results.arlpcg_beats_on_other_generators.is_empty() {
        md += "\n";
        md += &other_generators(results);
    }
    md += "\n";
    md += &controllability(results);
    if results
        .modes
        .iter()
        .any(|m| !m.controllability_by_judge.is_empty())
    {
        md += "\n";
        md += &outside_judges(results);
    }
    md += "\n";
    md += &each_run(results);
    md += "\n";
    md += &budget(results);
    md
}

/// Validation success per mode over its seeds, and P(arlpcg > baseline) there.
pub fn validation(results: &SeedResults) -> String {
    let mut md = String::from(
        "## Validation success over training seeds\n\n| mode | seeds | IQM [95% CI] | mean [95% CI] | P(arlpcg > it) [95% CI] |\n|---|---|---|---|---|\n",
    );
    for m in &results.modes {
        let seeds: Vec<String> = m.seeds.iter().map(u64::to_string).collect();
        let beaten = results
            .arlpcg_beats
            .iter()
            .find(|b| b.baseline == m.mode)
            .map_or("—".to_string(), |b| estimate(&b.probability));
        md += &format!(
            "| {} | {} | {} | {} | {beaten} |\n",
            m.mode,
            seeds.join(", "),
            estimate(&m.validation_iqm),
            estimate(&m.validation_mean)
        );
    }
    md
}

/// Every Solver on the other ARLPCG runs' λ = -1 levels.
pub fn other_generators(results: &SeedResults) -> String {
    let mut md = String::from(
        "## On other runs' Generators (λ = -1 levels of every ARLPCG Generator but the run's own)\n\n| mode | success: mean [95% CI] |\n|---|---|\n",
    );
    for m in &results.modes {
        if let Some(hard) = &m.other_generators_hard {
            md += &format!("| {} | {} |\n", m.mode, estimate(hard));
        }
    }
    md += "\n| P(arlpcg > baseline) on other runs' Generators | [95% CI] |\n|---|---|\n";
    md += &improvement_rows(&results.arlpcg_beats_on_other_generators, estimate);
    md += &generator_by_generator(results);
    md
}

/// Each adversarial mode's own pair at each λ, over its seeds.
pub fn controllability(results: &SeedResults) -> String {
    let mut md = String::from(
        "## Controllability over seeds (each run's own Generator and Solver)\n\n| mode |",
    );
    md += &aux_columns(&results.aux, 1);
    for m in &results.modes {
        if let Some(by_aux) = &m.controllability {
            md += &format!("| {} |", m.mode);
            for x in by_aux {
                md += &format!(" {} |", seeds_estimate(x));
            }
            md += "\n";
        }
    }
    md
}

/// The judges the runs never trained against, on each mode's levels at each λ.
pub fn outside_judges(results: &SeedResults) -> String {
    let mut md = String::from(
        "## Controllability over seeds for the outside judges (rule-pcg, scripted median and expert)\n\n| mode | judge |",
    );
    md += &aux_columns(&results.aux, 2);
    for m in results.modes.iter() {
        for j in &m.controllability_by_judge {
            md += &format!("| {} | {} |", m.mode, j.judge);
            for x in &j.success_ratio {
                md += &format!(" {} |", seeds_estimate(x));
            }
            md += "\n";
        }
    }
    md
}

/// One row per run: its validation, controllability, judges' drop and other Generators.
pub fn each_run(results: &SeedResults) -> String {
    let list = |xs: &[Option<f64>]| {
        xs.iter()
            .map(|x| x.map_or(String::from("— (no level)"), |x| format!("{x:.2}")))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut md = format!(
        "## Each run\n\n| run | mode | seed | validation (rule / Generator levels) | controllability λ = +1 … -1 | judges' median drop, all monotone (±{DROP_TOLERANCE}) | other Generators' λ = -1 |\n|---|---|---|---|---|---|---|\n"
    );
    for r in results.seeds.values().flatten() {
        let control = r.controllability.as_deref().map_or(String::from("—"), list);
        let drop = r
            .judges_drop(DROP_TOLERANCE)
            .map_or(String::from("—"), |(median, monotone)| {
                format!("{median:.2}, {}", if monotone { "yes" } else { "no" })
            });
        let others = r
            .other_generators_hard
            .map_or(String::from("—"), |x| format!("{x:.3}"));
        md += &format!(
            "| {} | {} | {} | {:.3} ({:.3} / {:.3}) | {control} | {drop} | {others} |\n",
            r.run,
            r.mode,
            r.seed,
            r.validation,
            r.validation_rule_levels,
            r.validation_generator_levels
        );
    }
    md
}

/// What was played, and how the intervals were drawn.
pub fn budget(results: &SeedResults) -> String {
    format!(
        "Budget: {} validation levels × {} runs (half rule levels, half from {}); {} levels × {} runs per λ. Intervals: stratified bootstrap over seeds, {} resamples.\n",
        results.budget.validation_tracks,
        results.budget.validation_trials,
        results.validation_generator,
        results.budget.tracks,
        results.budget.trials,
        arlpcg_core::statistics::over_seeds::RESAMPLES
    )
}
