//! A sharded evaluation's parts: what one shard writes ([`Part`]), and [`merge`], which checks
//! every part as strictly as a command-line argument (parts come from disk and may be damaged or
//! tampered with) and assembles the tables of the whole evaluation from them.

use std::collections::BTreeSet;
use std::path::PathBuf;

use anyhow::{Result, bail, ensure};
use serde::{Deserialize, Serialize};

use arlpcg_core::game::facts::facts;
use arlpcg_core::level::PolicyRef;
use arlpcg_core::level::profile::ProfileRecord;
use arlpcg_core::level::stats::SolverStats;

use super::{AUX_VALUES, Budget, PlayLayout, Results, assemble};

/// The file a shard writes (`eval --shard`) and `eval --merge` reads.
pub const PART_FILE: &str = "eval-part.json";
/// What an eval part file says it is.
const PART_FORMAT: &str = "arlpcg-eval-part";
/// 3: a part records the profile its levels were made for (a part of version 2 did not say).
const PART_VERSION: u32 = 3;
/// The most Solvers an evaluation compares (the paper's four modes, with room to spare).
const MOST_SOLVERS: usize = 16;
/// The most levels per table and runs per level a part may claim (ten times `--full`).
const MOST_LEVELS: u32 = 10_000;
const MOST_TRIALS: u32 = 10_000;

/// One shard's raw results: enough to rebuild the tables with the other shards.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Part {
    /// Always `arlpcg-eval-part`.
    pub format: String,
    /// The part's format version.
    pub version: u32,
    /// The arlpcg version that played it.
    pub arlpcg: String,
    /// This shard's index and the shard count.
    pub shard: [u64; 2],
    /// How much the whole evaluation plays.
    pub budget: Budget,
    /// The Generator whose levels are played.
    pub generator: PolicyRef,
    /// Each judge's name and Solver file (none for the scripted player), in table order.
    pub solvers: Vec<(String, Option<PolicyRef>)>,
    /// What every shard plays.
    pub layout: PlayLayout,
    /// (play index, its statistics) for this shard's plays.
    pub plays: Vec<(usize, SolverStats)>,
    /// The game profile every level was made and played for (`eval --profile`; absent: the
    /// built-in game).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<ProfileRecord>,
}

impl Part {
    /// A new part of shard `shard[0]` of `shard[1]`.
    pub fn new(
        shard: [u64; 2],
        budget: Budget,
        generator: PolicyRef,
        solvers: Vec<(String, Option<PolicyRef>)>,
        (layout, plays): (PlayLayout, Vec<(usize, SolverStats)>),
        profile: Option<ProfileRecord>,
    ) -> Self {
        Self {
            format: PART_FORMAT.into(),
            version: PART_VERSION,
            arlpcg: env!("CARGO_PKG_VERSION").into(),
            shard,
            budget,
            generator,
            solvers,
            layout,
            plays,
            profile,
        }
    }

    /// Checks what the part says of itself: format, budget, layout and every play's statistics
    /// within what an evaluation can hold, before anything is indexed or allocated from them.
    pub fn check(&self) -> Result<()> {
        ensure!(
            self.format == PART_FORMAT && self.version == PART_VERSION,
            "format {} version {}, expected {PART_FORMAT} version {PART_VERSION}",
            self.format,
            self.version
        );
        if let Some(record) = &self.profile {
            record
                .profile(self.layout.game)
                .map_err(|e| anyhow::anyhow!("profile: {e}"))?;
        }
        let [index, count] = self.shard;
        ensure!(
            count >= 1 && index < count,
            "shard {index}/{count} is not a shard (the index must be below the count)"
        );
        let b = self.budget;
        ensure!(
            (1..=MOST_LEVELS).contains(&b.tracks)
                && (1..=MOST_LEVELS).contains(&b.validation_tracks),
            "budget: levels per table must be 1 to {MOST_LEVELS}"
        );
        ensure!(
            (1..=MOST_TRIALS).contains(&b.trials)
                && (1..=MOST_TRIALS).contains(&b.validation_trials),
            "budget: runs per level must be 1 to {MOST_TRIALS}"
        );
        let layout = &self.layout;
        ensure!(
            !self.solvers.is_empty() && self.solvers.len() <= MOST_SOLVERS,
            "solvers: {} of them (1 to {MOST_SOLVERS})",
            self.solvers.len()
        );
        ensure!(
            layout.solvers.len() == self.solvers.len()
                && layout
                    .solvers
                    .iter()
                    .zip(&self.solvers)
                    .all(|(a, (b, _))| a == b),
            "layout.solvers does not name the part's solvers"
        );
        ensure!(
            layout.levels_per_aux.len() == AUX_VALUES.len()
                && layout.piece_means.len() == AUX_VALUES.len(),
            "layout: levels_per_aux and piece_means need one entry per λ ({})",
            AUX_VALUES.len()
        );
        let columns = facts(layout.game).piece_columns.len();
        for (a, (&n, means)) in layout
            .levels_per_aux
            .iter()
            .zip(&layout.piece_means)
            .enumerate()
        {
            ensure!(
                n <= b.tracks as usize,
                "layout.levels_per_aux[{a}]: {n} levels, more than the budget's {}",
                b.tracks
            );
            if let Some(means) = means {
                ensure!(
                    means.len() == columns && means.iter().all(|m| m.is_finite()),
                    "layout.piece_means[{a}]: needs {columns} finite values for a {} level",
                    layout.game.name()
                );
            }
        }
        ensure!(
            layout.validation_levels <= b.validation_tracks as usize
                && layout.validation_rule_levels <= layout.validation_levels,
            "layout: validation_levels {} (rule levels {}) do not fit the budget's {}",
            layout.validation_levels,
            layout.validation_rule_levels,
            b.validation_tracks
        );
        // Every count in the layout is now bounded by the budget, so this cannot overflow.
        let total = layout.play_count();
        ensure!(
            count <= total.max(1) as u64,
            "shard count {count} is more than the {total} plays of the evaluation"
        );
        for (i, stats) in &self.plays {
            ensure!(
                *i < total && *i as u64 % count == index,
                "play {i} does not belong to shard {index}/{count} of {total} plays"
            );
            stats
                .check(stats.failures_by_piece.len())
                .map_err(|e| anyhow::anyhow!("play {i}: {e}"))?;
        }
        Ok(())
    }
}

/// The tables of a sharded evaluation from every shard's part, each with the file it came from
/// (named in errors): every part checked, all from one evaluation, each shard once, every play
/// present.
pub fn merge(parts: Vec<(PathBuf, Part)>) -> Result<Results> {
    let Some((first_path, first)) = parts.first() else {
        bail!("no parts to merge");
    };
    for (path, part) in &parts {
        part.check()
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    }
    let count = first.shard[1];
    for (path, part) in &parts[1..] {
        if let Some(what) = difference(first, part) {
            bail!(
                "{} and {} come from different evaluations: their {what} differ",
                first_path.display(),
                path.display()
            );
        }
    }
    // As many indices as parts at most: nothing here is sized by the (checked, but large) count.
    let mut given = BTreeSet::new();
    for (path, part) in &parts {
        let index = part.shard[0];
        if !given.insert(index) {
            bail!(
                "shard {index}/{count} is given twice (again in {})",
                path.display()
            );
        }
    }
    let missing: Vec<String> = (0..count)
        .filter(|i| !given.contains(i))
        .take(10)
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
    let total = first.layout.play_count();
    let mut stats: Vec<Option<SolverStats>> = vec![None; total];
    for (path, part) in parts.iter() {
        for (i, s) in &part.plays {
            if stats[*i].replace(s.clone()).is_some() {
                bail!("{}: play {i} is given twice", path.display());
            }
        }
    }
    let stats: Vec<SolverStats> = stats
        .into_iter()
        .enumerate()
        .map(|(i, s)| s.ok_or_else(|| anyhow::anyhow!("play {i} is missing from its shard's part")))
        .collect::<Result<_>>()?;
    Ok(Results {
        profile: first.profile.clone(),
        ..assemble(first.budget, &first.generator.path, &first.layout, &stats)
    })
}

/// What differs between two parts that must come from one evaluation, if anything.
fn difference(a: &Part, b: &Part) -> Option<&'static str> {
    if a.arlpcg != b.arlpcg {
        Some("arlpcg version")
    } else if a.budget != b.budget {
        Some("budget")
    } else if a.generator.sha256 != b.generator.sha256 {
        Some("Generator")
    } else if a.solvers.len() != b.solvers.len()
        || a.solvers.iter().zip(&b.solvers).any(|(x, y)| {
            x.0 != y.0 || x.1.as_ref().map(|r| &r.sha256) != y.1.as_ref().map(|r| &r.sha256)
        })
    {
        Some("Solvers")
    } else if a.layout != b.layout {
        Some("levels")
    } else if a.shard[1] != b.shard[1] {
        Some("shard count")
    } else if a.profile.as_ref().map(|p| &p.sha256) != b.profile.as_ref().map(|p| &p.sha256) {
        Some("profiles")
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::services::eval::tables::tests::{layout, stats};
    use arlpcg_core::level::Game;

    fn reference(name: &str) -> PolicyRef {
        PolicyRef {
            path: name.into(),
            sha256: format!("{name:0>64}"),
        }
    }

    /// The parts of a `count`-shard evaluation of the test layout, play `i` succeeding in
    /// `i % 5` of 4 runs (at most 4).
    fn parts(count: u64) -> Vec<(PathBuf, Part)> {
        let layout = layout(Game::Platform);
        let total = layout.play_count();
        (0..count)
            .map(|index| {
                let plays = (0..total)
                    .filter(|i| *i as u64 % count == index)
                    .map(|i| (i, stats((i % 5).min(4) as u32, 4)))
                    .collect();
                let part = Part::new(
                    [index, count],
                    Budget::QUICK,
                    reference("gen"),
                    vec![
                        ("rule-pcg".into(), Some(reference("a"))),
                        ("arlpcg".into(), Some(reference("b"))),
                    ],
                    (layout.clone(), plays),
                    None,
                );
                (PathBuf::from(format!("part{index}")), part)
            })
            .collect()
    }

    fn merge_error(parts: Vec<(PathBuf, Part)>) -> String {
        format!("{:#}", merge(parts).expect_err("the merge is refused"))
    }

    #[test]
    fn shards_merge_into_the_whole_evaluation() {
        let whole = merge(parts(1)).unwrap();
        let mut shuffled = parts(3);
        shuffled.reverse();
        // Debug, not ==: a λ without levels holds NaN, which equals nothing.
        assert_eq!(
            format!("{:?}", merge(shuffled).unwrap()),
            format!("{whole:?}")
        );
        assert_eq!(
            whole.controllability[0].success_ratio, 0.0,
            "play 0: 0 of 4"
        );
        assert_eq!(
            whole.controllability[1].success_ratio, 0.375,
            "plays 1, 2: 1 and 2 of 4"
        );
    }

    #[test]
    fn missing_repeated_and_foreign_shards_are_named() {
        let mut three = parts(3);
        three.remove(1);
        assert!(merge_error(three).contains("shard 1/3 is missing"));
        let mut twice = parts(2);
        twice[1] = twice[0].clone();
        assert!(merge_error(twice).contains("shard 0/2 is given twice"));
        let mut other = parts(2);
        other[1].1.budget.trials = 7;
        assert!(merge_error(other).contains("their budget differ"));
    }

    /// Parts are read from disk: damaged or tampered numbers are refused with the file and the
    /// field named, before anything is indexed or allocated from them.
    #[test]
    fn tampered_parts_are_refused_before_use() {
        let tamper = |change: &dyn Fn(&mut Part)| {
            let mut all = parts(2);
            change(&mut all[1].1);
            merge_error(all)
        };
        type Change = dyn Fn(&mut Part);
        let cases: [(&Change, &str); 9] = [
            (&|p| p.shard = [5, 2], "shard 5/2 is not a shard"),
            (&|p| p.shard = [0, 0], "shard 0/0"),
            (
                &|p| p.shard[1] = 1 << 62,
                "shard count 4611686018427387904 is more than",
            ),
            (
                &|p| p.layout.levels_per_aux = vec![1 << 40; 5],
                "levels_per_aux[0]",
            ),
            (&|p| p.layout.piece_means.truncate(2), "one entry per λ"),
            (&|p| p.plays[0].0 = 1 << 40, "does not belong"),
            (&|p| p.plays[0].1.success_ratio = 7.5, "success_ratio 7.5"),
            (&|p| p.plays[0].1.trials = 0, "trials must be at least 1"),
            (&|p| p.budget.tracks = 1 << 30, "budget"),
        ];
        for (change, expected) in cases {
            let message = tamper(change);
            assert!(message.contains(expected), "{message:?} lacks {expected:?}");
            assert!(
                message.starts_with("part1") || message.contains("part1"),
                "{message}"
            );
        }
        let mut game = parts(2);
        game[1].1.layout.game = Game::Racing;
        assert!(merge_error(game).contains("piece_means"));
    }
}
