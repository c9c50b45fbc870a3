//! Field path ⇄ source position, from the span-preserving TOML parse.

use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// One step of a field path.
#[derive(Debug, Clone, PartialEq)]
pub enum Segment {
    Key(String),
    Index(usize),
}

/// A field path such as `link[1].joint.stiffness`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FieldPath(pub Vec<Segment>);

impl FieldPath {
    pub fn root() -> Self {
        FieldPath(Vec::new())
    }
    pub fn key(&self, k: &str) -> Self {
        let mut p = self.clone();
        p.0.push(Segment::Key(k.to_string()));
        p
    }
    pub fn index(&self, i: usize) -> Self {
        let mut p = self.clone();
        p.0.push(Segment::Index(i));
        p
    }
}

impl std::fmt::Display for FieldPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0.is_empty() {
            return f.write_str("(document)");
        }
        let mut first = true;
        for s in &self.0 {
            match s {
                Segment::Key(k) => {
                    if !first {
                        f.write_str(".")?;
                    }
                    f.write_str(k)?;
                }
                Segment::Index(i) => write!(f, "[{i}]")?,
            }
            first = false;
        }
        Ok(())
    }
}

/// Byte offset of the deepest element of `path` present in the document: the value itself when
/// it exists, otherwise the enclosing table.
pub fn offset_of(root: &Spanned<DeTable<'_>>, path: &FieldPath) -> usize {
    let mut offset = root.span().start;
    let mut table: Option<&DeTable<'_>> = Some(root.get_ref());
    let mut value: Option<&Spanned<DeValue<'_>>> = None;
    for seg in &path.0 {
        match seg {
            Segment::Key(k) => {
                let Some(t) = table else { break };
                let Some((key, v)) = t
                    .iter()
                    .find(|(key, _)| key.get_ref().as_ref() == k.as_str())
                else {
                    break;
                };
                // Tables opened with a [header] have a value span covering the body; point at
                // the key instead when the value is a table.
                offset = if v.get_ref().is_table() {
                    key.span().start
                } else {
                    v.span().start
                };
                value = Some(v);
            }
            Segment::Index(i) => {
                let Some(arr) = value.and_then(|v| v.get_ref().as_array()) else {
                    break;
                };
                let Some(v) = arr.get(*i) else { break };
                // Array-of-tables elements may carry an empty span: never move backwards.
                offset = offset.max(v.span().start);
                value = Some(v);
            }
        }
        table = value.and_then(|v| v.get_ref().as_table());
    }
    offset
}

/// Every float in the document that is not finite, with its path and byte offset.
pub fn non_finite_numbers(root: &Spanned<DeTable<'_>>) -> Vec<(FieldPath, usize)> {
    fn walk_value(v: &Spanned<DeValue<'_>>, path: FieldPath, out: &mut Vec<(FieldPath, usize)>) {
        match v.get_ref() {
            DeValue::Float(f) => {
                let s = f.as_str().trim_start_matches(['+', '-']);
                if s == "inf" || s == "nan" {
                    out.push((path, v.span().start));
                }
            }
            DeValue::Array(a) => {
                for (i, e) in a.iter().enumerate() {
                    walk_value(e, path.index(i), out);
                }
            }
            DeValue::Table(t) => walk_table(t, path, out),
            _ => {}
        }
    }
    fn walk_table(t: &DeTable<'_>, path: FieldPath, out: &mut Vec<(FieldPath, usize)>) {
        for (k, v) in t.iter() {
            walk_value(v, path.key(k.get_ref()), out);
        }
    }
    let mut out = Vec::new();
    walk_table(root.get_ref(), FieldPath::root(), &mut out);
    out
}
