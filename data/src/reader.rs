//! Scene files: TOML text → validated [`Scene`], with errors that point at file, line, column
//! and field.

use toml::de::DeTable;

use crate::error::{SceneError, line_column};
use crate::locate::{FieldPath, Segment, non_finite_numbers, offset_of};
use crate::scene::{Scene, SceneFile};
use crate::validate::limits::MAX_FILE_BYTES;
use crate::validate::scene_file::check_file;
use crate::validate::validate;

/// Parses and validates a scene. `source_name` is used in messages (usually the file path).
pub fn parse_scene(text: &str, source_name: &str) -> Result<Scene, SceneError> {
    let err_at = |offset: usize, path: String, message: String, expected: String| {
        let (line, column) = line_column(text, offset);
        SceneError {
            source_name: source_name.to_string(),
            line,
            column,
            path,
            message,
            expected,
        }
    };

    if text.len() > MAX_FILE_BYTES {
        return Err(err_at(
            0,
            "(document)".into(),
            format!("the file has {} bytes, above the limit", text.len()),
            format!("a scene file of at most {MAX_FILE_BYTES} bytes"),
        ));
    }

    let table = DeTable::parse(text).map_err(|e| {
        err_at(
            e.span().map_or(0, |s| s.start),
            "(document)".into(),
            format!("malformed TOML: {}", e.message().trim()),
            "valid TOML (see the annotated example in README.md)".into(),
        )
    })?;

    if let Some((path, offset)) = non_finite_numbers(&table).into_iter().next() {
        return Err(err_at(
            offset,
            path.to_string(),
            "non-finite number (inf or nan)".into(),
            "a finite number".into(),
        ));
    }

    let deserializer = toml::Deserializer::from(table.clone());
    let file: SceneFile = serde_path_to_error::deserialize(deserializer).map_err(|e| {
        let path = convert_path(e.path());
        let inner = e.inner();
        let message = inner.message().trim().to_string();
        let offset = inner
            .span()
            .map_or_else(|| offset_of(&table, &path), |s| s.start);
        let expected = expected_from_message(&message);
        err_at(offset, path.to_string(), message, expected)
    })?;

    let to_error = |issue: crate::validate::issue::Issue| {
        let offset = offset_of(&table, &issue.path);
        err_at(
            offset,
            issue.path.to_string(),
            issue.message,
            issue.expected,
        )
    };
    if let Some(issue) = check_file(&file).into_iter().next() {
        return Err(to_error(issue));
    }
    // check_file has established exactly one family with only its own tables: the
    // conversion cannot fail, and a failure would be a reader bug reported as one.
    let scene = Scene::try_from(file).map_err(|e| {
        err_at(
            0,
            "(document)".into(),
            e.to_string(),
            "exactly one model family per scene file".into(),
        )
    })?;
    if let Some(issue) = validate(&scene).into_iter().next() {
        return Err(to_error(issue));
    }
    Ok(scene)
}

fn convert_path(p: &serde_path_to_error::Path) -> FieldPath {
    use serde_path_to_error::Segment as S;
    FieldPath(
        p.iter()
            .filter_map(|s| match s {
                S::Seq { index } => Some(Segment::Index(*index)),
                S::Map { key } => Some(Segment::Key(key.clone())),
                S::Enum { variant } => Some(Segment::Key(variant.clone())),
                S::Unknown => None,
            })
            .collect(),
    )
}

fn expected_from_message(message: &str) -> String {
    if let Some(rest) = message.strip_prefix("missing field ") {
        return format!("the required field {rest} in this table");
    }
    if message.starts_with("unknown field") {
        if let Some((_, exp)) = message.split_once(", expected ") {
            return format!("a known field: {exp} (check spelling)");
        }
        if message.contains("there are no fields") {
            return "no fields in this table".into();
        }
    }
    if let Some((_, exp)) = message.split_once(", expected ") {
        return exp.to_string();
    }
    "the form documented in README.md".into()
}
