//! Where errors about a case text point: the line of a field, and the field of a parser error,
//! both from the spans of the TOML parser (`toml_edit`'s document of the text, and the span a
//! `toml` error carries).

use std::ops::Range;

use toml_edit::{ImDocument, Item, TableLike, Value};

use super::CaseError;

/// Where errors about a case text point: its file, and the line of a field.
pub(super) struct Locator<'a> {
    text: &'a str,
    file: &'a str,
    /// The text parsed with its spans; `None` when it is not TOML (a syntax error).
    doc: Option<ImDocument<&'a str>>,
}

/// What a parser error's span falls on: a key and its value, or a table.
struct Node<'d> {
    /// The dotted field with indices (`scene.sphere[1].x`), keys as written.
    field: String,
    /// The table it is, when it is one.
    table: Option<&'d dyn TableLike>,
    /// Whether that table opens with a header line (`[name]`, `[[name]]`).
    header: bool,
}

impl<'a> Locator<'a> {
    /// The locator of case text `text`, named `file` in errors.
    pub(super) fn new(text: &'a str, file: &'a str) -> Locator<'a> {
        Locator {
            text,
            file,
            doc: ImDocument::parse(text).ok(),
        }
    }

    /// The error `msg` about `field`, a dotted path with indices (`scene.sphere[1].x`), at the
    /// line that sets it ([`Locator::line`]).
    pub(super) fn error(&self, field: &str, msg: String) -> CaseError {
        CaseError {
            file: self.file.into(),
            line: self.line(field),
            field: field.into(),
            msg,
        }
    }

    /// `v` > 0 and finite, else the error "must be > 0" about `field`.
    pub(super) fn positive(&self, field: &str, v: f64) -> Result<(), CaseError> {
        if v > 0.0 && v.is_finite() {
            Ok(())
        } else {
            Err(self.error(field, format!("must be > 0, got {v}")))
        }
    }

    /// `v` >= 0 and finite, else the error "must be >= 0" about `field`.
    pub(super) fn non_negative(&self, field: &str, v: f64) -> Result<(), CaseError> {
        if v >= 0.0 && v.is_finite() {
            Ok(())
        } else {
            Err(self.error(field, format!("must be >= 0, got {v}")))
        }
    }

    /// Line (1-based) of the key that sets `field` (or the value it is inside of, as `x` holds
    /// `x[1]`), else of the header of the deepest table holding it, else 0.
    pub(super) fn line(&self, field: &str) -> usize {
        let Some(doc) = &self.doc else {
            return 0;
        };
        let mut table: &dyn TableLike = doc.as_table();
        let mut header = 0;
        let mut segs = segments(field).into_iter();
        while let Some(Seg::Key(k)) = segs.next() {
            let Some((key, item)) = table.get_key_value(&k) else {
                break;
            };
            match item {
                Item::Value(_) => return self.line_of(key.span()).unwrap_or(header),
                Item::Table(t) => {
                    header = self.line_of(t.span()).unwrap_or(header);
                    table = t;
                }
                Item::ArrayOfTables(a) => {
                    let Some(t) = segs.next().and_then(|s| match s {
                        Seg::Index(i) => a.get(i),
                        Seg::Key(_) => None,
                    }) else {
                        break;
                    };
                    header = self.line_of(t.span()).unwrap_or(header);
                    table = t;
                }
                Item::None => break,
            }
        }
        header
    }

    /// The case error of a parser error: its line from the error's span, its field what the
    /// span falls on. A tagged table (`[scene]`) is read whole and its error points at its
    /// header: the unknown key, the key holding the value of the wrong type or the array of
    /// the wrong length is found in it. A missing key is named, with the element of an array
    /// of tables that lacks it.
    pub(super) fn parse_error(&self, e: &toml::de::Error) -> CaseError {
        let msg = e.message().trim().to_string();
        let start = e.span().map(|s| s.start.min(self.text.len()));
        let mut line = start.map_or(0, |s| self.line_at(s));
        let node = match (&self.doc, start) {
            (Some(doc), Some(at)) => node_at(doc.as_table(), "", at),
            _ => None,
        };
        let mut field = match (&node, &self.doc) {
            (Some(n), _) => n.field.clone(),
            // the text is no document: the parser names no field, the line says what it holds
            (None, None) => field_on_line(self.text, line),
            (None, Some(_)) => "-".into(),
        };
        if let Some(Node {
            table: Some(t),
            header: true,
            field: table,
        }) = &node
        {
            if let Some(key) = self.offender(*t, table, &msg) {
                line = self.line(&key);
                field = key;
            }
        }
        if let Some(key) = msg
            .strip_prefix("missing field `")
            .and_then(|m| m.split('`').next())
        {
            match node.as_ref().and_then(|n| lacking(n.table?, &n.field, key)) {
                Some(element) => {
                    line = self.line(&element);
                    field = format!("{element}.{key}");
                }
                None if field == "-" => field = key.to_string(),
                None => field = format!("{field}.{key}"),
            }
        }
        CaseError {
            file: self.file.into(),
            line,
            field,
            msg: msg.split('\n').collect::<Vec<_>>().join("; "),
        }
    }

    /// The field, under the table `t` named `table`, that a serde message about the table as a
    /// whole is about: the unknown key it names, the first key whose value is the one it
    /// quotes (a whole value, else one inside an array or inline table), or the first array of
    /// the length it names.
    fn offender(&self, t: &dyn TableLike, table: &str, msg: &str) -> Option<String> {
        if let Some(key) = msg
            .strip_prefix("unknown field `")
            .and_then(|m| m.split('`').next())
        {
            return first_key(t, table, &|k, _| k == key);
        }
        let quoted = msg
            .strip_prefix("invalid type: ")
            .or_else(|| msg.strip_prefix("invalid value: "));
        if let Some(rest) = quoted {
            let is = |v: &Value| unexpected(v).is_some_and(|u| rest.starts_with(&format!("{u},")));
            return first_key(t, table, &|_, v| v.is_some_and(is))
                .or_else(|| first_key(t, table, &|_, v| v.is_some_and(|v| holds(v, &is))));
        }
        let length = msg
            .strip_prefix("invalid length ")
            .and_then(|m| m.split(',').next()?.parse::<usize>().ok())?;
        first_key(t, table, &|_, v| {
            v.and_then(Value::as_array)
                .is_some_and(|a| a.len() == length)
        })
    }

    /// The line (1-based) a span starts on.
    fn line_of(&self, span: Option<Range<usize>>) -> Option<usize> {
        span.map(|s| self.line_at(s.start))
    }

    /// The line (1-based) of byte `at` of the text.
    fn line_at(&self, at: usize) -> usize {
        self.text[..at.min(self.text.len())].matches('\n').count() + 1
    }
}

/// Whether `span` holds byte `at` (an empty span its own start).
fn holds_byte(span: Option<Range<usize>>, at: usize) -> bool {
    span.is_some_and(|s| s.start <= at && at < s.end.max(s.start + 1))
}

/// `prefix.key`, or `key` at the top.
fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

/// The innermost key (with its value) or table under `table` (named `prefix`) whose span
/// holds byte `at`.
fn node_at<'d>(table: &'d dyn TableLike, prefix: &str, at: usize) -> Option<Node<'d>> {
    for (name, item) in table.iter() {
        let (key, _) = table.get_key_value(name)?;
        let field = join(prefix, &key.display_repr());
        let tables: Vec<(String, &toml_edit::Table)> = match item {
            Item::Value(v) => {
                if holds_byte(key.span(), at) || holds_byte(v.span(), at) {
                    return Some(Node {
                        field,
                        table: v.as_inline_table().map(|t| t as &dyn TableLike),
                        header: false,
                    });
                }
                continue;
            }
            // a dotted key (`a.b = 1`) names its table on its own line
            Item::Table(t) if t.is_dotted() && holds_byte(key.span(), at) => {
                return Some(Node {
                    field,
                    table: Some(t),
                    header: false,
                });
            }
            Item::Table(t) => vec![(field, t)],
            Item::ArrayOfTables(a) => a
                .iter()
                .enumerate()
                .map(|(i, t)| (format!("{field}[{i}]"), t))
                .collect(),
            Item::None => continue,
        };
        for (field, t) in tables {
            if let Some(inner) = node_at(t, &field, at) {
                return Some(inner);
            }
            if holds_byte(t.span(), at) {
                return Some(Node {
                    field,
                    table: Some(t),
                    header: true,
                });
            }
        }
    }
    None
}

/// The first key, in the order of the text, of `table` (named `prefix`) or of the tables under
/// it for which `pick(key, value)` holds (the value `None` for a table): its dotted field with
/// indices.
fn first_key(
    table: &dyn TableLike,
    prefix: &str,
    pick: &dyn Fn(&str, Option<&Value>) -> bool,
) -> Option<String> {
    table.iter().find_map(|(name, item)| {
        let field = join(prefix, &table.get_key_value(name)?.0.display_repr());
        match item {
            Item::Value(v) => pick(name, Some(v)).then_some(field),
            Item::Table(_) if pick(name, None) => Some(field),
            Item::Table(t) => first_key(t, &field, pick),
            Item::ArrayOfTables(a) => a
                .iter()
                .enumerate()
                .find_map(|(i, t)| first_key(t, &format!("{field}[{i}]"), pick)),
            Item::None => None,
        }
    })
}

/// Whether an array or inline table `v` holds, at any depth, a value for which `is` holds.
fn holds(v: &Value, is: &dyn Fn(&Value) -> bool) -> bool {
    match v {
        Value::Array(a) => a.iter().any(|e| is(e) || holds(e, is)),
        Value::InlineTable(t) => t.iter().any(|(_, e)| is(e) || holds(e, is)),
        _ => false,
    }
}

/// How serde's messages quote the scalar `v` ("floating point `2.5`", "string \"one\""); none
/// for arrays, tables and dates, which they do not quote.
fn unexpected(v: &Value) -> Option<String> {
    use serde::de::Unexpected;
    let u = match v {
        Value::String(s) => Unexpected::Str(s.value()),
        Value::Integer(i) => Unexpected::Signed(*i.value()),
        Value::Float(f) => Unexpected::Float(*f.value()),
        Value::Boolean(b) => Unexpected::Bool(*b.value()),
        Value::Datetime(_) | Value::Array(_) | Value::InlineTable(_) => return None,
    };
    Some(u.to_string())
}

/// The first element `table.name[i]` of an array of tables (or of inline tables) in `table`
/// (named `prefix`) that lacks `key`.
fn lacking(table: &dyn TableLike, prefix: &str, key: &str) -> Option<String> {
    table.iter().find_map(|(name, item)| {
        let field = join(prefix, name);
        let i = match item {
            Item::ArrayOfTables(a) => a.iter().position(|t| !t.contains_key(key)),
            Item::Value(Value::Array(a)) => a
                .iter()
                .position(|e| e.as_inline_table().is_some_and(|t| !t.contains_key(key))),
            _ => None,
        }?;
        Some(format!("{field}[{i}]"))
    })
}

/// One step of a path into a TOML document.
#[derive(Clone, Debug, PartialEq)]
enum Seg {
    Key(String),
    Index(usize),
}

/// The steps of a dotted path with indices: `scene.sphere[1].x` → scene, sphere, 1, x.
fn segments(field: &str) -> Vec<Seg> {
    let mut out = Vec::new();
    for part in field.split('.') {
        let mut pieces = part.split('[');
        out.push(Seg::Key(pieces.next().unwrap_or("").to_string()));
        for p in pieces {
            if let Ok(n) = p.trim_end_matches(']').parse() {
                out.push(Seg::Index(n));
            }
        }
    }
    out
}

/// For a syntax error, where the text is no document and the parser names no field: what line
/// `line` (1-based) of `text` holds, `table.key` for a key line, the table for a header line,
/// "-" for anything else.
fn field_on_line(text: &str, line: usize) -> String {
    let header = |l: &str| {
        let rest = l.strip_prefix('[')?;
        let name = rest.trim_start_matches('[').split(']').next().unwrap_or("");
        Some(name.trim().to_string())
    };
    let mut table = String::new();
    for l in text.lines().take(line.saturating_sub(1)) {
        if let Some(name) = header(l.trim()) {
            table = name;
        }
    }
    let l = text.lines().nth(line.wrapping_sub(1)).unwrap_or("").trim();
    if let Some(name) = header(l) {
        return name;
    }
    match l.split_once('=') {
        Some((k, _)) => join(&table, k.trim()),
        None => "-".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PAIR: &str = include_str!("../../cases/verify/binary_collision.toml");

    /// The line of the second `[[scene.sphere]]`'s `x`, and of a key of a plain table.
    #[test]
    fn a_field_is_located_in_its_table_and_array_element() {
        let second_x = PAIR
            .lines()
            .position(|l| l.starts_with("x = [0.5005"))
            .unwrap()
            + 1;
        let at = Locator::new(PAIR, "p.toml");
        assert_eq!(at.line("scene.sphere[1].x[2]"), second_x);
        let kn = PAIR.lines().position(|l| l.starts_with("kn =")).unwrap() + 1;
        assert_eq!(at.line("contact.kn"), kn);
        // absent key: the header of the deepest table that would hold it
        let header = PAIR.lines().position(|l| l == "[contact]").unwrap() + 1;
        assert_eq!(at.line("contact.bogus"), header);
    }
}
