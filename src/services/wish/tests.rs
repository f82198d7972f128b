use super::*;
use arlpcg_core::game::Skill;

#[test]
fn constraints_read_back_what_they_write_and_refuse_bad_syntax() {
    for text in [
        "success 0.4..0.6", "b -1..1", "completed", "pieces 8..12", "climb >= 6", "drop <= 2.5",
        "pieces = 10", "success 0.4..0.6 for scripted-median", "hardest 0.66..1", "stride >= 0.5",
    ] {
        assert_eq!(Constraint::parse(text).unwrap().to_string(), text);
    }
    assert_eq!(
        Constraint::parse(" success  0.4 .. 0.6 ").unwrap(),
        Constraint {
            attribute: Attribute::Success(None),
            low: 0.4,
            high: 0.6
        }
    );
    assert_eq!(
        Constraint::parse("pieces 10").unwrap().to_string(),
        "pieces = 10"
    );
    for (text, expected) in [
        ("speed 1..2", "`speed` is not an attribute"),
        ("success 0.6..0.4", "is empty"),
        ("pieces 12..8", "is empty"),
        ("success 0.5..", "is not a number"),
        ("success 1.5..2", "lies within 0..1"),
        ("b NaN..1", "`NaN` is not a number"),
        ("done", "has no range"),
        ("climb >= 6 for scripted-median", "only `success`"),
        ("success 0..1 for nobody", "is not a judge"),
        ("completed 0..1", "takes no range"),
    ] {
        let err = Constraint::parse(text).unwrap_err();
        assert!(err.contains(expected), "{text}: {err}");
    }
}

#[test]
fn a_wish_list_refuses_what_cannot_hold_before_any_search() {
    let want =
        Want::parse("pieces 8..12, climb >= 6 and success 0.4..0.6 for scripted-median").unwrap();
    assert_eq!(want.constraints.len(), 3);
    assert_eq!(want.judges(), vec![Judge::Scripted(Skill::Median)]);
    assert_eq!(want.reads(), Reads::Runs);
    assert_eq!(Want::parse(&want.to_string()).unwrap(), want);
    for (text, expected) in [
        ("", "empty"),
        (" , ,", "empty"),
        ("pieces 8..10, pieces 12..14", "cannot both hold"),
        ("climb >= 6, climb <= 2", "cannot both hold"),
    ] {
        let err = Want::parse(text).unwrap_err();
        assert!(err.contains(expected), "{text}: {err}");
    }
    let long = "pieces 8..12, ".repeat(200);
    assert!(Want::parse(&long).unwrap_err().contains("at most"));
    // An attribute of the other game is refused for this one, naming this one's.
    let curve = Want::parse("curve >= 20").unwrap();
    let err = curve.fit(Game::Platform).unwrap_err();
    assert!(err.contains("jump") && err.contains("platform"), "{err}");
    assert!(curve.fit(Game::Racing).is_ok());
    assert!(
        Want::parse("stride >= 0")
            .unwrap()
            .fit(Game::Racing)
            .is_err()
    );
    // b is checked on made levels, never searched for: a search refuses it by name.
    let b = Want::parse("climb >= 4, b >= 0").unwrap();
    assert!(b.fit(Game::Platform).is_ok(), "a check may read b");
    let err = b.fit_search(Game::Platform).unwrap_err();
    assert!(
        err.starts_with("`b >= 0`") && err.contains("--check"),
        "{err}"
    );
    assert!(
        Want::parse("climb >= 4")
            .unwrap()
            .fit_search(Game::Platform)
            .is_ok()
    );
}

#[test]
fn plain_words_read_as_a_wish_list_and_unused_words_are_named() {
    let reading = words::read(
        "A long, easy level that climbs, with one hard jump near the end!",
        Game::Platform,
    )
    .unwrap();
    assert_eq!(
        reading.want.to_string(),
        "pieces >= 10, success 0.75..1, climb >= 5, hardest 0.6..1"
    );
    assert!(reading.unknown.is_empty() && reading.other_game.is_empty());
    let reading = words::read("a twisty road, hard for experts, purple", Game::Racing).unwrap();
    assert_eq!(
        reading.want.to_string(),
        "curviness >= 0.5, success 0..0.6 for scripted-expert"
    );
    assert_eq!(reading.unknown, vec!["purple".to_string()]);
    let reading = words::read("a curvy level of about 9 blocks, in blue", Game::Platform).unwrap();
    assert_eq!(reading.want.to_string(), "pieces 7..11");
    assert_eq!(reading.other_game, vec!["curvy".to_string()]);
    assert_eq!(reading.unknown, vec!["in".to_string(), "blue".to_string()]);
    for (sentence, expected) in [
        ("purple elephants", "says nothing"),
        ("", "says nothing"),
        ("an easy but hard level", "cannot both hold"),
    ] {
        let err = words::read(sentence, Game::Platform).unwrap_err();
        assert!(err.contains(expected), "{sentence}: {err}");
    }
    let flood = "word ".repeat(10_000);
    assert!(
        words::read(&flood, Game::Platform)
            .unwrap_err()
            .contains("at most")
    );
}

/// docs/wish.md lists every phrase of the vocabulary, and each of its example sentences reads
/// as the wish list it gives.
#[test]
fn the_documented_vocabulary_and_examples_are_what_the_reader_reads() {
    let doc = include_str!("../../../docs/wish.md");
    for (phrase, _) in words::VOCABULARY {
        assert!(
            doc.contains(&format!("`{phrase}`")),
            "docs/wish.md does not list `{phrase}`"
        );
    }
    let examples = doc
        .split("### Examples")
        .nth(1)
        .expect("an Examples section");
    let mut read = 0;
    for row in examples
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| sentence"))
    {
        let cells: Vec<&str> = row.trim_matches('|').split('|').map(str::trim).collect();
        let [sentence, game, want] = cells[..] else {
            panic!("`{row}` is not a row of three cells");
        };
        let game: Game = game.parse().unwrap();
        let reading = words::read(sentence, game).unwrap();
        assert_eq!(reading.want.to_string(), want, "{sentence}");
        assert!(
            reading.unknown.is_empty(),
            "{sentence}: {:?}",
            reading.unknown
        );
        read += 1;
    }
    assert!(read >= 10, "{read} examples");
}

/// The shipped ask sets read whole: every wish list parses and fits its game, every sentence
/// reads as the wish list the set gives for it.
#[test]
fn the_shipped_ask_sets_read_as_they_say() {
    for (game, asks, sentences) in [(Game::Platform, 43, 15), (Game::Racing, 41, 15)] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("results/{game}/wish/asks.yaml"));
        let set = score::AskSet::load(&path, game).unwrap();
        assert_eq!(set.len(), asks, "{game}");
        assert_eq!(
            set.iter().filter(|(_, _, s)| *s).count(),
            sentences,
            "{game}"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("asks.yaml");
    std::fs::write(
        &file,
        "asks:\n- ask: a short level\n  reads_as: pieces <= 9\n",
    )
    .unwrap();
    let err = score::AskSet::load(&file, Game::Platform).unwrap_err();
    assert!(
        err.contains("asks[0]") && err.contains("reads as `pieces <= 7`"),
        "{err}"
    );
}
