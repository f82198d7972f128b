//! A level that meets a wish list ([`crate::services::wish::Want`]): candidates are built
//! round by round (one draw at each λ or curve in turn, first of the seed's own scene, then of
//! other seeds' scenes, [`OWN_SCENE_ROUNDS`]), those whose pieces already
//! miss a constraint are passed over unplayed, the rest are played and measured; the first
//! that meets every constraint (and that some run completed) is certified and records its want.
//! A want no candidate meets is named: each constraint's closest value, the candidates tried.

use arlpcg_core::level::pacing::AuxCurve;
use arlpcg_core::level::profile::Profile;
use arlpcg_core::level::stats::SolverStats;
use arlpcg_core::level::{Level, MeasuredConstraint, WantRecord};

use super::LevelSource;
use crate::services::generation::{AuxAsk, LevelRequest};
use crate::services::panel::Judge;
use crate::services::verify::{self, Solver, Watch};
use crate::services::wish::{Attribute, Evidence, Miss, Reads, Strictness, Want};

/// Rounds of candidates, one at each λ or curve per round: a want the pieces alone miss costs
/// no plays, so many scenes are looked at before the search gives up.
pub const ROUNDS: u32 = 48;
/// Rounds drawn in the seed's own scene; later rounds (unless the goal is given or pieces
/// are kept) take the whole scene (start, goal) of another seed, `seed ^ (round << 48)`, as
/// `generate --target-success` does, and the level records that seed: a long or climbing
/// level needs a goal far or high enough.
pub const OWN_SCENE_ROUNDS: u32 = 4;
/// The most candidates played (each `trials` runs): a want that reads runs gives up there.
pub const MAX_PLAYED: u32 = 40;

/// How a wish list is searched for.
pub struct Search<'a> {
    /// What is wanted.
    pub want: &'a Want,
    /// Who plays: the wish list's runs and the certificate (none: nothing is played, which
    /// only a wish list on the pieces alone allows).
    pub solver: Option<&'a Solver<'a>>,
    /// The players of the judges a `success for JUDGE` names.
    pub judges: &'a [(Judge, Solver<'a>)],
    /// Runs per played candidate.
    pub trials: u32,
}

/// No candidate met the wish list.
#[derive(Debug, thiserror::Error)]
#[error(
    "no level met `{want}` in {tried} candidates ({played} played): {closest}; ask for less, or give more room (--aux, another --seed)"
)]
pub struct Unmet {
    /// The constraints (by index) the closest candidate missed or could not be measured on.
    pub missed: Vec<usize>,
    /// The closest candidate itself, with its runs (`stats`) when it was played: what a
    /// benchmark scores as the search's level (its quality), though it is never written.
    pub closest_level: Option<Box<Level>>,
    want: String,
    tried: u32,
    played: u32,
    closest: String,
}

/// What the search came closest to: each constraint's closest miss, which constraints some
/// candidate met, and the candidate that missed least.
struct Closest {
    each: Vec<Option<Miss>>,
    met_somewhere: Vec<bool>,
    best: Option<Candidate>,
}

/// The candidate that missed least.
struct Candidate {
    /// How far it missed, all constraints together.
    far: f64,
    /// What it was (`describe`).
    what: String,
    /// Why it missed each constraint it missed.
    whys: Vec<String>,
    /// The constraints (by index) it missed or could not be measured on.
    missed: Vec<usize>,
    /// The level itself, with its runs when it was played.
    level: Level,
}

impl Closest {
    fn new(constraints: usize) -> Self {
        Closest {
            each: vec![None; constraints],
            met_somewhere: vec![false; constraints],
            best: None,
        }
    }

    /// A candidate `level` that missed `misses` of the constraints it was measured on (those
    /// reading at most `measured`), `draw` its draw and `stats` its runs when it was played.
    fn note(
        &mut self,
        want: &Want,
        (level, draw, stats): (&Level, u32, Option<&SolverStats>),
        misses: &[(usize, Miss)],
        measured: Reads,
    ) {
        let mut far = 0.0;
        let mut unmeasured = Vec::new();
        for (index, constraint) in want.constraints.iter().enumerate() {
            let missed = misses.iter().find(|(i, _)| *i == index).map(|(_, m)| m);
            match missed {
                Some(miss) => {
                    far += miss.distance;
                    let slot = &mut self.each[index];
                    if slot
                        .as_ref()
                        .is_none_or(|best| miss.distance < best.distance)
                    {
                        *slot = Some(miss.clone());
                    }
                }
                None if constraint.attribute.reads() <= measured => {
                    self.met_somewhere[index] = true
                }
                // Not measured: as far as a miss that could not be measured.
                None => {
                    far += 1.0;
                    unmeasured.push(index);
                }
            }
        }
        if self.best.as_ref().is_none_or(|best| far < best.far) {
            self.best = Some(Candidate {
                far,
                what: describe(level, draw),
                whys: misses.iter().map(|(_, m)| m.why.clone()).collect(),
                missed: misses.iter().map(|(i, _)| *i).chain(unmeasured).collect(),
                level: Level {
                    stats: stats.cloned(),
                    ..level.clone()
                },
            });
        }
    }

    /// The constraints no candidate met, each by its closest value, and the closest candidate.
    fn describe(&self) -> String {
        let never: Vec<String> = self
            .each
            .iter()
            .zip(&self.met_somewhere)
            .filter(|(_, met)| !**met)
            .filter_map(|(miss, _)| miss.as_ref().map(|m| format!("never met: {}", m.why)))
            .collect();
        let best = self.best.as_ref().map(|best| {
            format!(
                "the closest candidate ({}) missed {}",
                best.what,
                best.whys.join("; ")
            )
        });
        never.into_iter().chain(best).collect::<Vec<_>>().join("; ")
    }
}

impl Search<'_> {
    /// The first candidate of `request`'s seed that meets the wish list; `Ok(None)` when
    /// `watch.stop` cut the plays short.
    pub fn level(
        &self,
        source: LevelSource,
        request: &LevelRequest,
        watch: &Watch,
    ) -> anyhow::Result<Option<Level>> {
        let request = &self.bounded(source, request);
        let asks = self.asks(source, request);
        let knobs = self.knobs(source, request);
        let mut closest = Closest::new(self.want.constraints.len());
        let (mut tried, mut played) = (0u32, 0u32);
        let mut last_error = None;
        let fixed_scene = request.goal.is_some() || request.keep.is_some();
        let wants_runs = self.want.reads() > Reads::Pieces;
        'rounds: for round in 0..ROUNDS {
            let (scene, draw) = match round < OWN_SCENE_ROUNDS || fixed_scene {
                true => (request.seed, round),
                false => (request.seed ^ (u64::from(round) << 48), 0),
            };
            for aux in &asks {
                if wants_runs && played >= MAX_PLAYED {
                    break 'rounds;
                }
                let candidate = LevelRequest {
                    seed: scene,
                    draw,
                    aux: aux.clone(),
                    knobs: knobs.clone(),
                    ..request.clone()
                };
                let mut level = match source.level(&candidate) {
                    Ok(level) => level,
                    Err(e) => {
                        last_error = Some(e);
                        continue;
                    }
                };
                tried += 1;
                // What the pieces alone say first: a miss there is not worth playing.
                let on_pieces = self.misses(&level, &Evidence::default(), Some(Reads::Pieces));
                if !on_pieces.is_empty() {
                    closest.note(self.want, (&level, draw, None), &on_pieces, Reads::Pieces);
                    continue;
                }
                let Some(solver) = self.solver else {
                    let measured = self.want.measured(&level, &Evidence::default());
                    return Ok(Some(self.record(level, measured, draw, tried)));
                };
                let seed = request.seed;
                let Some(stats) = verify::verify_watched(&level, solver, self.trials, seed, watch)?
                else {
                    return Ok(None);
                };
                let Some(judged) = self.play_judges(&level, seed, watch)? else {
                    return Ok(None);
                };
                played += 1;
                let evidence = Evidence {
                    stats: Some(&stats),
                    panel: None,
                    judges: &judged,
                };
                let misses = self.misses(&level, &evidence, None);
                closest.note(
                    self.want,
                    (&level, draw, Some(&stats)),
                    &misses,
                    Reads::Panel,
                );
                if !misses.is_empty() || stats.successes == 0 {
                    continue;
                }
                let measured = self.want.measured(&level, &evidence);
                level.stats = Some(stats);
                let level = verify::certified(level, solver, seed)?;
                return Ok(Some(self.record(level, measured, draw, tried)));
            }
        }
        if tried == 0 {
            return Err(last_error.unwrap_or_else(|| anyhow::anyhow!("no candidate was built")));
        }
        let described = closest.describe();
        let (missed, closest_level) = closest.best.map_or((Vec::new(), None), |best| {
            (best.missed, Some(Box::new(best.level)))
        });
        Err(Unmet {
            missed,
            closest_level,
            want: self.want.to_string(),
            tried,
            played,
            closest: described,
        }
        .into())
    }

    /// `level` with its want recorded: the wish list, the draw, the candidates tried and each
    /// constraint's measured value.
    fn record(
        &self,
        mut level: Level,
        measured: Vec<MeasuredConstraint>,
        draw: u32,
        tried: u32,
    ) -> Level {
        level.want = Some(WantRecord {
            asked: self.want.to_string(),
            draw,
            tried,
            measured,
        });
        level
    }

    /// The constraints `level` misses (of those that read at most `reads`), by index.
    fn misses(
        &self,
        level: &Level,
        evidence: &Evidence,
        reads: Option<Reads>,
    ) -> Vec<(usize, Miss)> {
        self.want
            .constraints
            .iter()
            .enumerate()
            .filter(|(_, c)| reads.is_none_or(|r| c.attribute.reads() <= r))
            .filter_map(|(i, c)| Some((i, c.miss(level, evidence, Strictness::Value)?)))
            .collect()
    }

    /// Each judge's runs on `level`; none when `watch.stop` cut them short.
    fn play_judges(
        &self,
        level: &Level,
        seed: u64,
        watch: &Watch,
    ) -> anyhow::Result<Option<Vec<(Judge, SolverStats)>>> {
        let mut judged = Vec::new();
        for (judge, player) in self.judges {
            match verify::verify_watched(level, player, self.trials, seed, watch)? {
                Some(stats) => judged.push((*judge, stats)),
                None => return Ok(None),
            }
        }
        Ok(Some(judged))
    }

    /// `request` with its profile holding every piece to each upper bound asked of an attribute
    /// a piece range bounds (`curve <= 25`: `segments.max_curve: 25`; `jump <= 8`:
    /// `blocks.max_distance: 8`) where that is tighter than the profile's own range: the
    /// Generator builds within the ranges it is given, and its levels rarely keep under such a
    /// bound of their own accord (the shipped racing Generator turns its most, 30°, somewhere on
    /// nearly every track). The level records the profile it was made under.
    fn bounded(&self, source: LevelSource, request: &LevelRequest) -> LevelRequest {
        let given = request
            .profile
            .clone()
            .unwrap_or_else(|| Profile::default_of(source.game()));
        let held = self
            .want
            .constraints
            .iter()
            .fold(given.clone(), |profile, c| {
                let tighter = c.attribute.profile_bound().and_then(|field| {
                    let (now, _) = profile.value(field)?;
                    (c.high < now).then(|| profile.with_value(field, c.high))?
                });
                tighter.unwrap_or(profile)
            });
        LevelRequest {
            profile: (held != given).then_some(held).or(request.profile.clone()),
            ..request.clone()
        }
    }

    /// The λ (or curves) tried in each round: the one asked, else (a Generator's) the ladder
    /// from +1 to -1 in quarters, nearest first to the λ the wish list's success suggests,
    /// after the curves that put the hardest part where a `hardest` constraint asks.
    fn asks(&self, source: LevelSource, request: &LevelRequest) -> Vec<Option<AuxAsk>> {
        if request.aux.is_some() || matches!(source, LevelSource::Rules(_)) {
            return vec![request.aux.clone()];
        }
        let suggested = self
            .want
            .constraints
            .iter()
            .find(|c| matches!(c.attribute, Attribute::Success(_)))
            .map_or(0.0, |c| 2.0 * middle(c.low, c.high, (0.0, 1.0)) - 1.0);
        let mut ladder: Vec<f64> = (0..=8).map(|k| 1.0 - 0.25 * f64::from(k)).collect();
        ladder.sort_by(|a, b| (a - suggested).abs().total_cmp(&(b - suggested).abs()));
        let mut asks: Vec<Option<AuxAsk>> = Vec::new();
        if let Some(hardest) = self
            .want
            .constraints
            .iter()
            .find(|c| c.attribute == Attribute::Hardest)
        {
            let at = middle(hardest.low, hardest.high, (0.0, 1.0));
            let easy = suggested.max(0.0);
            // Easy everywhere but a hard stretch around `at`; easy up to `at`, hard after.
            let bump = [
                (0.0, easy),
                ((at - 0.2).max(0.0), easy),
                (at, -1.0),
                ((at + 0.2).min(1.0), easy),
                (1.0, easy),
            ];
            let ramp = [
                (0.0, easy),
                ((at - 0.1).max(0.0), easy),
                (at, -1.0),
                (1.0, -1.0),
            ];
            for points in [&bump[..], &ramp[..]] {
                let mut unique: Vec<(f64, f64)> = Vec::new();
                for &p in points {
                    if unique.last().is_none_or(|last| last.0 < p.0) {
                        unique.push(p);
                    }
                }
                if let Ok(curve) = AuxCurve::new(unique) {
                    asks.push(Some(AuxAsk::Curve(curve)));
                }
            }
        }
        asks.extend(ladder.into_iter().map(|aux| Some(AuxAsk::Flat(aux))));
        asks
    }

    /// The style knobs: the ones asked, else for a Generator that takes knobs, each knob a
    /// constraint speaks of set to the middle of its range.
    fn knobs(&self, source: LevelSource, request: &LevelRequest) -> Vec<f32> {
        let LevelSource::Generator(generator) = source else {
            return request.knobs.clone();
        };
        if generator.knobs == 0 || request.knobs.iter().any(|k| *k != 0.0) {
            return request.knobs.clone();
        }
        let names = generator.game.shape().knobs();
        names
            .iter()
            .take(generator.knobs)
            .map(|name| {
                self.want
                    .constraints
                    .iter()
                    .find(|c| c.attribute == Attribute::Knob(name))
                    .map_or(0.0, |c| middle(c.low, c.high, (-1.0, 1.0)) as f32)
            })
            .collect()
    }
}

/// The middle of `[low, high]` within `domain`.
fn middle(low: f64, high: f64, domain: (f64, f64)) -> f64 {
    let (low, high) = (low.max(domain.0), high.min(domain.1));
    (low + high) / 2.0
}

/// A candidate, as the search names it: its scene's seed, draw and λ.
fn describe(level: &Level, draw: u32) -> String {
    let aux = match (level.aux, &level.pacing) {
        (Some(aux), _) => format!("λ {aux:+.2}"),
        (None, Some(pacing)) => format!("λ curve {}", pacing.curve),
        (None, None) => "the rules".into(),
    };
    format!(
        "seed {}, draw {draw}, {aux}",
        level.seed.unwrap_or_default()
    )
}
