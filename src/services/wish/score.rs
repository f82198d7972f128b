//! A score the field can compare (`arlpcg bench`): a set of asks (wish lists or sentences),
//! a few levels searched for each, and what they came to, in the PCG Benchmark's three
//! figures: quality (the share of levels certified: some recorded run completes them),
//! controllability (the share meeting every constraint, and per attribute) and diversity (the
//! mean distance between levels over pairs, against plain levels of the same Generator at
//! λ = 0); with the time each level took. docs/wish.md says how each is measured.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::{Attribute, Evidence, Want, words};
use arlpcg_core::level::{Game, Level};

/// An ask set's file: `asks:` a list, each `want: WISHES` or `ask: SENTENCE`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AskSet {
    /// The asks, in order.
    pub asks: Vec<AskEntry>,
}

/// One ask of a set: one of its fields.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AskEntry {
    /// A wish list.
    #[serde(default)]
    pub want: Option<String>,
    /// A sentence in plain words.
    #[serde(default)]
    pub ask: Option<String>,
    /// The wish list the sentence reads as, where the set says (checked when it is read).
    #[serde(default)]
    pub reads_as: Option<String>,
}

impl AskSet {
    /// Reads an ask set for `game`: each ask as written, its wish list, and whether it is a
    /// sentence; the error names the file and the ask.
    pub fn load(path: &std::path::Path, game: Game) -> Result<Vec<(String, Want, bool)>, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        let set: AskSet = serde_yaml::from_str(&text).map_err(|e| {
            format!(
                "{}: {e} (an ask set holds `asks:`, each `want: WISHES` or `ask: SENTENCE`)",
                path.display()
            )
        })?;
        if set.asks.is_empty() {
            return Err(format!("{}: asks: the set is empty", path.display()));
        }
        set.asks
            .iter()
            .enumerate()
            .map(|(i, entry)| {
                let (text, want, sentence) = match (&entry.want, &entry.ask) {
                    (Some(text), None) if entry.reads_as.is_none() => {
                        (text.clone(), Want::parse(text), false)
                    }
                    (None, Some(text)) => {
                        let want =
                            words::read(text, game).map(|r| r.want).and_then(|w| {
                                match &entry.reads_as {
                                    Some(said) if *said != w.to_string() => Err(format!(
                                        "`{text}` reads as `{w}`, not as `{said}` (reads_as)"
                                    )),
                                    _ => Ok(w),
                                }
                            });
                        (text.clone(), want, true)
                    }
                    _ => (
                        String::new(),
                        Err("give `want:` or `ask:` (with `reads_as:`), one of them".to_string()),
                        false,
                    ),
                };
                want.and_then(|w| w.fit_search(game).map(|()| w))
                    .map(|w| (text, w, sentence))
                    .map_err(|e| format!("{}: asks[{i}]: {e}", path.display()))
            })
            .collect()
    }
}

/// What one search came to.
pub struct Outcome {
    /// The level it ended with: the one it kept, else its closest candidate (none when it
    /// built none).
    pub level: Option<Level>,
    /// Whether the level met every constraint (the search kept it).
    pub met: bool,
    /// When it met nothing, the constraints (by index) its closest candidate missed.
    pub missed: Vec<usize>,
    /// Seconds from the ask to the certified level (or to giving up).
    pub seconds: f64,
}

/// The bench's figures for one game's ask set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Score {
    /// The game.
    pub game: Game,
    /// Asks in the set, and of them sentences.
    pub asks: usize,
    /// Of the asks, those written in plain words.
    pub sentences: usize,
    /// Levels searched for each ask (seeds 0, 1, ...).
    pub levels_per_ask: u32,
    /// Levels searched in all.
    pub searched: usize,
    /// The share of searches whose level (kept, or else the closest candidate) is certified (a
    /// recorded run completes it).
    pub quality: f64,
    /// The share of searches whose level meets every constraint of its ask.
    pub controllability: f64,
    /// Per attribute: the share of its constraints met by the searched level.
    pub by_attribute: BTreeMap<String, f64>,
    /// The mean distance between two of the searches' levels ([`distance`]) over pairs.
    pub diversity: f64,
    /// The same for plain levels of the Generator at λ = 0, one per seed searched.
    pub plain_diversity: f64,
    /// Median seconds from an ask to its certified level.
    pub median_seconds: f64,
}

/// Scores `outcomes`, one per (ask, seed), against `plain` levels of the same Generator.
pub fn score(
    game: Game,
    asks: &[(String, Want, bool)],
    levels_per_ask: u32,
    outcomes: &[Outcome],
    plain: &[Level],
) -> Score {
    let searched = outcomes.len();
    let share = |n: usize, of: usize| if of == 0 { 0.0 } else { n as f64 / of as f64 };
    let certified = outcomes
        .iter()
        .filter(|o| {
            let stats = o.level.as_ref().and_then(|l| l.stats.as_ref());
            stats.is_some_and(|s| s.certificate.is_some())
        })
        .count();
    let mut met_all = 0;
    let mut by_attribute: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    for (index, outcome) in outcomes.iter().enumerate() {
        let want = &asks[index / levels_per_ask as usize].1;
        // A kept level met every constraint when it was measured (with its judges' runs,
        // which the file does not hold); a search that kept none is read by its closest
        // candidate.
        let all = outcome.met;
        for (i, constraint) in want.constraints.iter().enumerate() {
            let met = all || !outcome.missed.contains(&i);
            let entry = by_attribute
                .entry(constraint.attribute.to_string())
                .or_default();
            entry.0 += usize::from(met);
            entry.1 += 1;
        }
        met_all += usize::from(all);
    }
    let ended: Vec<&Level> = outcomes.iter().filter_map(|o| o.level.as_ref()).collect();
    let mut seconds: Vec<f64> = outcomes.iter().map(|o| o.seconds).collect();
    seconds.sort_by(f64::total_cmp);
    Score {
        game,
        asks: asks.len(),
        sentences: asks.iter().filter(|(_, _, sentence)| *sentence).count(),
        levels_per_ask,
        searched,
        quality: share(certified, searched),
        controllability: share(met_all, searched),
        by_attribute: by_attribute
            .into_iter()
            .map(|(name, (met, of))| (name, share(met, of)))
            .collect(),
        diversity: mean_distance(&ended),
        plain_diversity: mean_distance(&plain.iter().collect::<Vec<_>>()),
        median_seconds: seconds.get(seconds.len() / 2).copied().unwrap_or(0.0),
    }
}

/// The distance between two levels of one game: the mean, over the attributes their pieces
/// alone give (pieces, length, climb, drop, the style measures, and jump or curve), of the
/// difference in units of [`spread`].
pub fn distance(a: &Level, b: &Level) -> f64 {
    let attributes: Vec<Attribute> = Attribute::all(a.game().shape())
        .into_iter()
        .filter(|x| x.reads() == super::Reads::Pieces)
        .collect();
    let none = Evidence::default();
    let differences: Vec<f64> = attributes
        .iter()
        .filter_map(|x| {
            let (va, vb) = (x.value(a, &none).ok()?, x.value(b, &none).ok()?);
            Some((va - vb).abs() / spread(*x))
        })
        .collect();
    differences.iter().sum::<f64>() / differences.len().max(1) as f64
}

/// What one unit of difference is, per attribute, for [`distance`]: about the spread of the
/// shipped Generators' levels between λ = +1 and -1 (docs/wish.md).
pub fn spread(attribute: Attribute) -> f64 {
    match attribute {
        Attribute::Pieces => 5.0,
        Attribute::Length => 50.0,
        Attribute::Climb | Attribute::Drop => 5.0,
        Attribute::Jump => 2.5,
        Attribute::Curve => 15.0,
        _ => 1.0,
    }
}

/// The mean [`distance`] over every pair of `levels` (0 for fewer than two).
pub fn mean_distance(levels: &[&Level]) -> f64 {
    let mut total = 0.0;
    let mut pairs = 0usize;
    for (i, a) in levels.iter().enumerate() {
        for b in &levels[i + 1..] {
            total += distance(a, b);
            pairs += 1;
        }
    }
    if pairs == 0 {
        0.0
    } else {
        total / pairs as f64
    }
}
