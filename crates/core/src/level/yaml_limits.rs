//! Limits a YAML text must keep before serde_yaml builds anything from it: nesting at most
//! [`MAX_DEPTH`] deep and no aliases. serde_yaml 0.9 enforces its own depth limit only after
//! libyaml has parsed the whole document (100,000 levels took 45 s, growing with the square of
//! the depth), and it expands every alias (a 4 MB file of repeated aliases grew to gigabytes).
//! Here libyaml's event stream (the same parser serde_yaml uses, so the two agree on what the
//! text means) is read one event at a time and abandoned at the first event past a limit.
//! Syntax errors are left to serde_yaml, which reports them with their line.

use std::mem::MaybeUninit;

/// The deepest nesting of mappings and sequences a level or configuration may have (theirs is
/// at most 4).
pub const MAX_DEPTH: usize = 32;

/// Checks `text` against the limits: `Err("what, line N")`.
pub fn check(text: &str) -> Result<(), String> {
    let mut parser = MaybeUninit::<unsafe_libyaml::yaml_parser_t>::uninit();
    // SAFETY: the parser is initialized before use and deleted once, after the last event; it
    // reads `text` (valid for the whole function) through a pointer and length; every event
    // it returns is deleted before the next is asked for.
    unsafe {
        if unsafe_libyaml::yaml_parser_initialize(parser.as_mut_ptr()).fail {
            return Err("cannot start the YAML parser (out of memory)".into());
        }
        let parser = parser.as_mut_ptr();
        unsafe_libyaml::yaml_parser_set_input_string(parser, text.as_ptr(), text.len() as _);
        let mut depth = 0usize;
        let verdict = loop {
            let mut event = MaybeUninit::<unsafe_libyaml::yaml_event_t>::uninit();
            if unsafe_libyaml::yaml_parser_parse(parser, event.as_mut_ptr()).fail {
                break Ok(()); // a syntax error: serde_yaml names it
            }
            let event = event.as_mut_ptr();
            let line = (*event).start_mark.line as usize + 1;
            let outcome = match (*event).type_ {
                unsafe_libyaml::YAML_SEQUENCE_START_EVENT
                | unsafe_libyaml::YAML_MAPPING_START_EVENT => {
                    depth += 1;
                    (depth > MAX_DEPTH).then(|| {
                        Err(format!(
                            "nested more than {MAX_DEPTH} levels deep (line {line})"
                        ))
                    })
                }
                unsafe_libyaml::YAML_SEQUENCE_END_EVENT
                | unsafe_libyaml::YAML_MAPPING_END_EVENT => {
                    depth = depth.saturating_sub(1);
                    None
                }
                unsafe_libyaml::YAML_ALIAS_EVENT => Some(Err(format!(
                    "aliases (*name) are not allowed: write the values out (line {line})"
                ))),
                unsafe_libyaml::YAML_STREAM_END_EVENT => Some(Ok(())),
                _ => None,
            };
            unsafe_libyaml::yaml_event_delete(event);
            if let Some(verdict) = outcome {
                break verdict;
            }
        };
        unsafe_libyaml::yaml_parser_delete(parser);
        verdict
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordinary_documents_pass() {
        assert_eq!(check("a: [1, {b: 2}]\nc:\n  - d: 3\n"), Ok(()));
        assert_eq!(check("anchored: &x 3\n"), Ok(()));
        // Syntax errors are serde_yaml's to report.
        assert_eq!(check("a: [1, 2\n"), Ok(()));
    }

    #[test]
    fn deep_nesting_is_refused_at_the_first_level_too_many() {
        let ok = format!("{}{}", "[".repeat(MAX_DEPTH), "]".repeat(MAX_DEPTH));
        assert_eq!(check(&ok), Ok(()));
        // 100,000 levels: parsed in full, this took serde_yaml 45 s.
        let deep = format!("a: {}1{}", "[".repeat(100_000), "]".repeat(100_000));
        let err = check(&deep).unwrap_err();
        assert!(err.contains("more than 32 levels deep (line 1)"), "{err}");
        let block = (0..40)
            .map(|k| format!("{}k{k}:\n", " ".repeat(k)))
            .collect::<String>();
        let err = check(&block).unwrap_err();
        assert!(err.contains("(line 33)"), "{err}");
    }

    #[test]
    fn aliases_are_refused() {
        let bomb = format!("a: &a [1, 2, 3]\nb: [{}]\n", vec!["*a"; 1000].join(", "));
        let err = check(&bomb).unwrap_err();
        assert!(
            err.contains("aliases (*name) are not allowed") && err.contains("line 2"),
            "{err}"
        );
    }
}
