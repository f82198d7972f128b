//! What `generate` is asked besides λ: the style knobs `--aux` names, and the wish list of
//! `--want`, `--want-file` or `--ask` (said as read), each with its part of the file name.

use anyhow::Result;

use crate::services::generation::GeneratorPolicy;
use crate::services::wish::{self, Want};
use crate::shells::cli::GenerateArgs;

/// The style knobs `--aux` names, in the game's order (0, no preference, where not named), for
/// a Generator that takes them; an error for a knob the game or the Generator does not have.
pub(super) fn knob_values(
    args: &GenerateArgs,
    generator: Option<&GeneratorPolicy>,
) -> Result<Vec<f32>> {
    let (asked, knobs) = asked_knobs(args);
    let names: Vec<&str> = knobs.iter().map(|k| k.name).collect();
    for (name, _) in asked {
        if !names.contains(&name.as_str()) {
            return Err(crate::shells::common::UsageError(format!(
                "--aux {name}: the {} game's knobs are {} (and difficulty, λ)",
                args.game,
                names.join(", ")
            ))
            .into());
        }
    }
    let takes = generator.map_or(0, |g| g.knobs);
    if let (Some((name, _)), 0) = (asked.first(), takes) {
        match generator {
            None => anyhow::bail!(
                "--aux {name}: the rules take no knobs (a Generator trained with them does)"
            ),
            Some(g) => anyhow::bail!(
                "--aux {name}: the Generator {} was trained without knobs (its config's generator.rewards.knobs)",
                g.reference.path
            ),
        }
    }
    Ok(names
        .iter()
        .take(takes)
        .map(|knob| {
            asked
                .iter()
                .find(|(name, _)| name == knob)
                .map_or(0.0, |(_, value)| *value as f32)
        })
        .collect())
}

/// The wish list of --want, --want-file or --ask (said as read, with each word it did not
/// use), checked against the game's attributes; none without one.
pub(super) fn wanted(args: &GenerateArgs) -> Result<Option<Want>> {
    let usage = |message: String| crate::shells::common::UsageError(message);
    let want = match (&args.want, &args.want_file, &args.sentence) {
        (Some(want), _, _) => want.clone(),
        (None, Some(file), _) => wish::load(file).map_err(usage)?,
        (None, None, Some(sentence)) => {
            let reading = wish::words::read(sentence, args.game).map_err(usage)?;
            crate::warn!("read as: {}", reading.want);
            if !reading.unknown.is_empty() {
                crate::warn!(
                    "not used (not in the vocabulary, docs/wish.md): {}",
                    reading.unknown.join(", ")
                );
            }
            if !reading.other_game.is_empty() {
                crate::warn!(
                    "not used (nothing of {} levels): {}",
                    args.game,
                    reading.other_game.join(", ")
                );
            }
            reading.want
        }
        (None, None, None) => return Ok(None),
    };
    want.fit_search(args.game).map_err(usage)?;
    Ok(Some(want))
}

/// `_want-` and a short hash of the wish list as asked (the file records it).
pub(super) fn want_suffix(args: &GenerateArgs) -> String {
    let asked = match (&args.want, &args.want_file, &args.sentence) {
        (Some(want), _, _) => want.to_string(),
        (_, Some(file), _) => file.display().to_string(),
        (_, _, Some(sentence)) => sentence.clone(),
        _ => return String::new(),
    };
    let hash = arlpcg_core::level::sha256_hex(asked.as_bytes());
    format!("_want-{}", &hash[..8])
}

/// The knobs `--aux` names (name, value), and the game's knobs.
fn asked_knobs(
    args: &GenerateArgs,
) -> (
    &[(String, f64)],
    &'static [arlpcg_core::game::generator::Knob],
) {
    use arlpcg_core::game::generator::GeneratorGame;
    let asked = args.aux.as_ref().map_or(&[][..], |aux| &aux.knobs[..]);
    (asked, arlpcg_core::for_game!(args.game, G => G::KNOBS))
}

/// `_name<value>` for each knob `--aux` names, in the game's order.
pub(super) fn knob_suffix(args: &GenerateArgs) -> String {
    let (asked, knobs) = asked_knobs(args);
    knobs
        .iter()
        .filter_map(|knob| asked.iter().find(|(name, _)| name == knob.name))
        .map(|(name, value)| format!("_{name}{value:.2}"))
        .collect()
}
