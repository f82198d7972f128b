//! The level file, format `arlpcg-level` version 1 (YAML): the source of truth for a level.
//!
//! Loading checks everything and names the file, the field and, where it can, the line of the
//! first problem. A designer may write a level by hand giving only the relative parameters: the
//! resolved transforms (`position`, `heading` of each block) and the goal are then computed.

use std::io::Read;
use std::path::{Path, PathBuf};

use super::platform;
use super::{Level, PolicyRef};

mod file;
use file::LevelFile;

/// The `format` every level file declares.
pub const FORMAT_NAME: &str = "arlpcg-level";
/// The version of the format this build reads and writes.
pub const FORMAT_VERSION: u32 = 1;
/// Level files larger than this are refused before parsing (real ones are a few kB).
pub const MAX_FILE_BYTES: u64 = 4 << 20;
/// Resolved positions and headings in a file must match the parameters this closely.
const TRANSFORM_TOLERANCE: f64 = 1e-3;

/// A level file that could not be loaded.
#[derive(Debug, thiserror::Error)]
#[error("{}: {problem}", path.display())]
pub struct LoadError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong with it.
    pub problem: Problem,
}

/// What is wrong with a level file.
#[derive(Debug, thiserror::Error)]
pub enum Problem {
    /// The file could not be read.
    #[error("cannot read the file: {0}")]
    Io(#[from] std::io::Error),
    /// The file holds nothing.
    #[error("the file is empty")]
    Empty,
    /// The path is not a regular file.
    #[error("not a regular file (a folder, FIFO, socket or device)")]
    NotAFile,
    /// The file is over the size limit.
    #[error("the file is larger than {} MiB; a level file is a few kB", MAX_FILE_BYTES >> 20)]
    TooLarge,
    /// The file is not UTF-8; the byte offset of the first bad byte.
    #[error("not a text file (invalid UTF-8 at byte {0})")]
    NotText(usize),
    /// The file is not an arlpcg level (no mapping, or a wrong or missing `format` or `version`).
    #[error("not an arlpcg level: {0}")]
    NotALevel(String),
    /// The file is of a format version this build does not read.
    #[error("format version {0} is not supported: this arlpcg reads version {FORMAT_VERSION}")]
    UnsupportedVersion(String),
    /// A syntax, type or range error found while parsing (serde_yaml names field and line).
    #[error("{0}")]
    Parse(String),
    /// A rule of the level broken by otherwise well-formed values.
    #[error("{field}: {message}{}", line.map(|l| format!(" (line {l})")).unwrap_or_default())]
    Invalid {
        /// The field, as a path into the file (`segments[2].aux`).
        field: String,
        /// The field's line in the file, when found.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
}

/// Reads and validates a level file.
pub fn load(path: &Path) -> Result<Level, LoadError> {
    load_pinned(path).map(|(level, _)| level)
}

/// [`load`], and the file pinned by the hash of the bytes read (what a kept prefix records).
pub fn load_pinned(path: &Path) -> Result<(Level, PolicyRef), LoadError> {
    let fail = |problem| LoadError {
        path: path.to_path_buf(),
        problem,
    };
    let meta = std::fs::metadata(path).map_err(|e| fail(e.into()))?;
    if !meta.is_file() {
        return Err(fail(Problem::NotAFile));
    }
    let file = std::fs::File::open(path).map_err(|e| fail(e.into()))?;
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| fail(e.into()))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(fail(Problem::TooLarge));
    }
    let reference = PolicyRef::pinned(path.display().to_string(), &bytes);
    let text = String::from_utf8(bytes)
        .map_err(|e| fail(Problem::NotText(e.utf8_error().valid_up_to())))?;
    Ok((parse(&text).map_err(fail)?, reference))
}

/// Parses and validates the text of a level file.
pub fn parse(text: &str) -> Result<Level, Problem> {
    // A byte-order mark (some Windows editors write one) is not part of the document.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if text.trim().is_empty() {
        return Err(Problem::Empty);
    }
    super::yaml_limits::check(text).map_err(Problem::Parse)?;
    check_header(text)?;
    let file: LevelFile = serde_yaml::from_str(text).map_err(|e| Problem::Parse(e.to_string()))?;
    file.into_level(text)
}

/// The level as the text of a level file (deterministic: same level, same bytes).
pub fn to_string(level: &Level) -> String {
    let file = LevelFile::from_level(level);
    serde_yaml::to_string(&file).expect("a level always serializes")
}

/// Checks `format` and `version` before anything else, so that a file of another kind or
/// version gets that error rather than a confusing one about its fields.
fn check_header(text: &str) -> Result<(), Problem> {
    let document: serde_yaml::Value =
        serde_yaml::from_str(text).map_err(|e| Problem::Parse(format!("invalid YAML: {e}")))?;
    let serde_yaml::Value::Mapping(fields) = document else {
        return Err(Problem::NotALevel(format!(
            "expected a YAML mapping starting with `format: {FORMAT_NAME}`, found {}",
            describe_value(&document)
        )));
    };
    match fields.get("format") {
        Some(serde_yaml::Value::String(name)) if name == FORMAT_NAME => {}
        Some(other) => {
            return Err(Problem::NotALevel(format!(
                "format is {}, expected {FORMAT_NAME}",
                describe_value(other)
            )));
        }
        None => {
            return Err(Problem::NotALevel(format!(
                "missing field `format: {FORMAT_NAME}`"
            )));
        }
    }
    match fields.get("version") {
        Some(serde_yaml::Value::Number(n)) if n.as_u64() == Some(FORMAT_VERSION as u64) => {}
        Some(other) => return Err(Problem::UnsupportedVersion(describe_value(other))),
        None => return Err(Problem::NotALevel("missing field `version`".into())),
    }
    check_counts(&fields, text)?;
    check_source_fields(fields.get("source"), text)
}

/// Lists longer than a level may hold are refused before they are parsed into pieces (a huge
/// list would otherwise be read, and for a road, laid out, first).
fn check_counts(fields: &serde_yaml::Mapping, text: &str) -> Result<(), Problem> {
    for (key, max) in [
        ("blocks", platform::MAX_BLOCKS),
        ("segments", super::racing::MAX_SEGMENTS),
        ("obstacles", super::racing::MAX_OBSTACLES),
    ] {
        if let Some(serde_yaml::Value::Sequence(items)) = fields.get(key)
            && items.len() > max
        {
            return Err(Problem::Invalid {
                field: key.into(),
                line: line_of_key(text, key),
                message: format!(
                    "the level has {} {key}: at most {max} are allowed",
                    items.len()
                ),
            });
        }
    }
    Ok(())
}

/// The fields each `source.kind` needs, named with their path and line (serde's message for a
/// tagged variant has neither).
fn check_source_fields(source: Option<&serde_yaml::Value>, text: &str) -> Result<(), Problem> {
    let Some(serde_yaml::Value::Mapping(source)) = source else {
        return Ok(());
    };
    let needed: &[&str] = match source.get("kind").and_then(|k| k.as_str()) {
        Some("rules" | "racing-rules") => &["rules"],
        Some("policy") => &["generator"],
        Some("kept") => &["pieces", "from", "generator"],
        _ => &[],
    };
    match needed.iter().find(|field| !source.contains_key(**field)) {
        Some(field) => Err(Problem::Invalid {
            field: format!("source.{field}"),
            line: line_of_key(text, "source"),
            message: "missing".into(),
        }),
        None => Ok(()),
    }
}

fn describe_value(value: &serde_yaml::Value) -> String {
    let text = serde_yaml::to_string(value).unwrap_or_default();
    let text = text.trim();
    if text.len() > 40 {
        format!("{}...", &text[..text.floor_char_boundary(40)])
    } else {
        text.to_string()
    }
}

/// A rule of the level broken at `field` (and `line`, where known).
fn invalid(field: String, line: Option<usize>, message: String) -> Problem {
    Problem::Invalid {
        field,
        line,
        message,
    }
}

/// The 1-based line of a top-level `key:`, if written in block style.
fn line_of_key(text: &str, key: &str) -> Option<usize> {
    text.lines()
        .position(|l| {
            l.strip_prefix(key)
                .is_some_and(|rest| rest.starts_with(':'))
        })
        .map(|i| i + 1)
}

/// The 1-based line where item `index` of the top-level sequence `key` starts, if the sequence
/// is written in block style (one `- ` per item, as arlpcg writes it).
fn line_of_item(text: &str, key: &str, index: usize) -> Option<usize> {
    let start = line_of_key(text, key)?;
    let mut item_indent = None;
    let mut seen = 0;
    for (i, line) in text.lines().enumerate().skip(start) {
        let content = line.trim_start();
        if content.is_empty() || content.starts_with('#') {
            continue;
        }
        let indent = line.len() - content.len();
        let is_item = content == "-" || content.starts_with("- ");
        let items_at = *item_indent.get_or_insert(indent);
        if indent < items_at || (indent == 0 && !is_item) {
            return None;
        }
        if is_item && indent == items_at {
            if seen == index {
                return Some(i + 1);
            }
            seen += 1;
        }
    }
    None
}

#[cfg(test)]
mod tests;
