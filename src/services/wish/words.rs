//! Plain words into a wish list (`generate --ask "a long, easy level that climbs, with one hard
//! jump near the end"`): an offline, deterministic reader over a vocabulary table. Each phrase
//! of the table stands for constraints in the wish-list language (per shape of pieces where
//! the two games differ), for a judge the last difficulty word is about, or for nothing (`a`,
//! `level`, `with`). A word no phrase covers is named, never dropped. docs/wish.md lists the
//! vocabulary with examples; its table is [`VOCABULARY`].

use arlpcg_core::level::{Game, ShapeKind};

use super::{Attribute, Constraint, MAX_TEXT, Want};
use crate::services::panel::Judge;
use arlpcg_core::game::Skill;

/// What a phrase stands for.
#[derive(Debug, Clone, Copy)]
pub enum Meaning {
    /// Nothing to measure: glue words.
    Glue,
    /// How hard, as the success of the player that verifies (or of the judge a following
    /// phrase names): a constraint on `success`.
    Difficulty(&'static str),
    /// Constraints in the wish-list language, for blocks levels and for road levels (none: the
    /// phrase says nothing of that game's levels).
    Shaped {
        /// For blocks (platform).
        blocks: Option<&'static str>,
        /// For a road (racing).
        road: Option<&'static str>,
    },
    /// The player the difficulty word before it is about.
    For(Judge),
}

const fn both(text: &'static str) -> Meaning {
    Meaning::Shaped {
        blocks: Some(text),
        road: Some(text),
    }
}

const fn blocks(text: &'static str) -> Meaning {
    Meaning::Shaped {
        blocks: Some(text),
        road: None,
    }
}

const fn road(text: &'static str) -> Meaning {
    Meaning::Shaped {
        blocks: None,
        road: Some(text),
    }
}

const fn shaped(blocks: &'static str, road: &'static str) -> Meaning {
    Meaning::Shaped {
        blocks: Some(blocks),
        road: Some(road),
    }
}

const NOVICE: Meaning = Meaning::For(Judge::Scripted(Skill::Novice));
const MEDIAN: Meaning = Meaning::For(Judge::Scripted(Skill::Median));
const EXPERT: Meaning = Meaning::For(Judge::Scripted(Skill::Expert));

/// The vocabulary: each phrase (words separated by spaces) and what it stands for. At each
/// word the longest phrase that matches is read. The sizes come from the shipped Generators'
/// levels (docs/wish.md: their quartiles over 20 seeds at λ = +1, 0 and -1).
pub const VOCABULARY: &[(&str, Meaning)] = &[
    // How hard.
    ("very easy", Meaning::Difficulty("success 0.9..1")),
    ("easy", Meaning::Difficulty("success 0.75..1")),
    ("gentle", Meaning::Difficulty("success 0.75..1")),
    ("relaxed", Meaning::Difficulty("success 0.75..1")),
    ("medium", Meaning::Difficulty("success 0.4..0.8")),
    ("moderate", Meaning::Difficulty("success 0.4..0.8")),
    ("fair", Meaning::Difficulty("success 0.4..0.8")),
    ("hard", Meaning::Difficulty("success 0..0.6")),
    ("difficult", Meaning::Difficulty("success 0..0.6")),
    ("tough", Meaning::Difficulty("success 0..0.6")),
    ("challenging", Meaning::Difficulty("success 0..0.6")),
    ("very hard", Meaning::Difficulty("success 0..0.35")),
    ("brutal", Meaning::Difficulty("success 0..0.35")),
    // For whom.
    ("for a beginner", NOVICE),
    ("for beginners", NOVICE),
    ("for a novice", NOVICE),
    ("for novices", NOVICE),
    ("for an average player", MEDIAN),
    ("for average players", MEDIAN),
    ("for most players", MEDIAN),
    ("for an expert", EXPERT),
    ("for experts", EXPERT),
    // How long.
    ("short", shaped("pieces <= 7", "pieces <= 13")),
    ("quick", shaped("pieces <= 7", "pieces <= 13")),
    ("long", shaped("pieces >= 10", "pieces >= 18")),
    ("very long", shaped("pieces >= 13", "pieces >= 22")),
    // Up and down.
    ("climbs", shaped("climb >= 5", "climb >= 15")),
    ("climbing", shaped("climb >= 5", "climb >= 15")),
    ("goes up", shaped("climb >= 5", "climb >= 15")),
    ("uphill", shaped("climb >= 5", "climb >= 15")),
    ("rises", shaped("climb >= 5", "climb >= 15")),
    ("descends", shaped("drop >= 4", "drop >= 15")),
    ("goes down", shaped("drop >= 4", "drop >= 15")),
    ("downhill", shaped("drop >= 4", "drop >= 15")),
    ("flat", shaped("steps <= -0.3", "elevation <= -0.4")),
    // Where the hard part is.
    ("near the end", both("hardest 0.6..1")),
    ("at the end", both("hardest 0.6..1")),
    ("towards the end", both("hardest 0.6..1")),
    ("toward the end", both("hardest 0.6..1")),
    ("near the start", both("hardest 0..0.4")),
    ("at the start", both("hardest 0..0.4")),
    ("at the beginning", both("hardest 0..0.4")),
    ("near the beginning", both("hardest 0..0.4")),
    ("in the middle", both("hardest 0.25..0.75")),
    ("hard jump", Meaning::Glue),
    ("hard part", Meaning::Glue),
    ("hard bit", Meaning::Glue),
    ("hard section", Meaning::Glue),
    ("hard turn", Meaning::Glue),
    ("hard corner", Meaning::Glue),
    ("tricky jump", Meaning::Glue),
    ("tricky part", Meaning::Glue),
    ("tricky turn", Meaning::Glue),
    // Platform: the jumps.
    ("long jumps", blocks("stride >= 0.4")),
    ("big jumps", blocks("stride >= 0.4")),
    ("leaps", blocks("stride >= 0.4")),
    ("short hops", blocks("stride <= -0.4")),
    ("small jumps", blocks("stride <= -0.4")),
    ("hops", blocks("stride <= -0.4")),
    ("stairs", blocks("steps >= 0.2")),
    ("steps", blocks("steps >= 0.2")),
    // Racing: the road.
    ("curvy", road("curviness >= 0.5")),
    ("twisty", road("curviness >= 0.5")),
    ("winding", road("curviness >= 0.5")),
    ("sharp turns", road("curviness >= 0.5")),
    ("straight", road("curviness <= 0.25")),
    ("sweeping", road("curviness <= 0.25")),
    ("bumpy", road("elevation >= -0.25")),
    ("hilly", road("elevation >= -0.25")),
    // Glue.
    ("a", Meaning::Glue),
    ("an", Meaning::Glue),
    ("the", Meaning::Glue),
    ("and", Meaning::Glue),
    ("but", Meaning::Glue),
    ("with", Meaning::Glue),
    ("that", Meaning::Glue),
    ("which", Meaning::Glue),
    ("it", Meaning::Glue),
    ("is", Meaning::Glue),
    ("has", Meaning::Glue),
    ("one", Meaning::Glue),
    ("of", Meaning::Glue),
    ("some", Meaning::Glue),
    ("level", Meaning::Glue),
    ("track", Meaning::Glue),
    ("road", Meaning::Glue),
    ("course", Meaning::Glue),
    ("please", Meaning::Glue),
];

/// A sentence read: its wish list, the words no phrase covered, and the phrases that say
/// nothing of this game's levels.
#[derive(Debug, Clone, PartialEq)]
pub struct Reading {
    /// The wish list the sentence stands for.
    pub want: Want,
    /// Words no phrase of the vocabulary covers, in order.
    pub unknown: Vec<String>,
    /// Phrases of the vocabulary that say nothing of this game's levels (`curvy` of blocks).
    pub other_game: Vec<String>,
}

/// Reads `sentence` for `game`'s levels. An error when it is too long, says nothing the
/// vocabulary knows, or asks two things that cannot both hold (`easy` and `hard`).
pub fn read(sentence: &str, game: Game) -> Result<Reading, String> {
    if sentence.len() > MAX_TEXT {
        return Err(format!(
            "a sentence of {} bytes: at most {MAX_TEXT}",
            sentence.len()
        ));
    }
    let words: Vec<String> = sentence
        .split(|c: char| !(c.is_alphanumeric() || c == '.' || c == '-'))
        .map(|w| w.trim_matches(['.', '-']).to_lowercase())
        .filter(|w| !w.is_empty())
        .collect();
    let shape = game.shape();
    let mut constraints: Vec<Constraint> = Vec::new();
    let mut unknown = Vec::new();
    let mut other_game = Vec::new();
    // The difficulty constraint a following `for ...` phrase names the player of.
    let mut last_difficulty: Option<usize> = None;
    let mut at = 0;
    while at < words.len() {
        if let Some((taken, constraint)) = number_of_pieces(&words[at..]) {
            constraints.push(constraint);
            at += taken;
            continue;
        }
        let Some((phrase, meaning)) = longest_phrase(&words[at..]) else {
            unknown.push(words[at].clone());
            at += 1;
            continue;
        };
        let taken = phrase.split(' ').count();
        match meaning {
            Meaning::Glue => {}
            Meaning::Difficulty(text) => {
                last_difficulty = Some(constraints.len());
                constraints.push(Constraint::parse(text)?);
            }
            Meaning::For(judge) => match last_difficulty.take() {
                Some(index) => constraints[index].attribute = Attribute::Success(Some(judge)),
                None => unknown.push(phrase.to_string()),
            },
            Meaning::Shaped { blocks, road } => {
                let text = match shape {
                    ShapeKind::Blocks => blocks,
                    ShapeKind::Road => road,
                };
                match text {
                    Some(text) => constraints.extend(Want::parse(text)?.constraints),
                    None => other_game.push(phrase.to_string()),
                }
            }
        }
        at += taken;
    }
    if constraints.is_empty() {
        return Err(format!(
            "`{}` says nothing the vocabulary knows (docs/wish.md lists it)",
            sentence.trim()
        ));
    }
    // A constraint said twice (`long, very long`) is kept once.
    let mut kept: Vec<Constraint> = Vec::new();
    for c in constraints {
        if !kept.contains(&c) {
            kept.push(c);
        }
    }
    let want = Want { constraints: kept };
    want.consistent()
        .map_err(|e| format!("`{}`: {e}", sentence.trim()))?;
    Ok(Reading {
        want,
        unknown,
        other_game,
    })
}

/// The longest phrase of the vocabulary that `words` begin with.
fn longest_phrase(words: &[String]) -> Option<(&'static str, Meaning)> {
    VOCABULARY
        .iter()
        .filter(|(phrase, _)| {
            let parts: Vec<&str> = phrase.split(' ').collect();
            parts.len() <= words.len() && parts.iter().zip(words).all(|(p, w)| p == w)
        })
        .max_by_key(|(phrase, _)| phrase.split(' ').count())
        .copied()
}

/// `N pieces`, `about N pieces`, `at least N pieces`, `at most N pieces` (`blocks`,
/// `segments` or `pieces`): the words taken and the constraint.
fn number_of_pieces(words: &[String]) -> Option<(usize, Constraint)> {
    const PIECES: [&str; 6] = ["pieces", "piece", "blocks", "block", "segments", "segment"];
    let (lead, taken): (&str, usize) = match words {
        [a, b, ..] if a == "at" && (b == "least" || b == "most") => (b, 2),
        [a, ..] if a == "about" || a == "around" => (a, 1),
        _ => ("", 0),
    };
    let n: f64 = words
        .get(taken)?
        .parse()
        .ok()
        .filter(|n: &f64| n.is_finite() && *n >= 1.0)?;
    if !PIECES.contains(&words.get(taken + 1)?.as_str()) {
        return None;
    }
    let (low, high) = match lead {
        "least" => (n, f64::INFINITY),
        "most" => (1.0, n),
        "about" | "around" => ((n - 2.0).max(1.0), n + 2.0),
        _ => (n, n),
    };
    Some((
        taken + 2,
        Constraint {
            attribute: Attribute::Pieces,
            low,
            high,
        },
    ))
}
