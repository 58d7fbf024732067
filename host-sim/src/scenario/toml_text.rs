//! Working on TOML text: setting a dotted key (`--set`) and telling where an error is
//! (line, column, dotted field). The location helpers are public: sweep files report their
//! errors the same way.

/// `s` on one line (TOML messages span several).
pub fn one_line(s: &str) -> String {
    s.trim().replace('\n', " ")
}

/// Parses an override value as TOML (`0.2`, `"exact"`, `[1, 2]`, `true`), falling back to
/// a bare string (`exact`).
pub(super) fn parse_override_value(raw: &str) -> toml::Value {
    let doc = format!("v = {raw}");
    match toml::from_str::<toml::Table>(&doc) {
        Ok(mut t) => t.remove("v").unwrap_or(toml::Value::String(raw.to_owned())),
        Err(_) => toml::Value::String(raw.to_owned()),
    }
}

/// Why a `--set` key cannot be set (the messages name the key and the part of it).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SetPathError {
    /// An empty part (`radio..loss`, a leading or trailing dot).
    #[error("bad key `{key}`")]
    BadKey {
        /// The key.
        key: String,
    },
    /// A part inside an array that is not a number.
    #[error("`{part}` in `{key}` must be an array index")]
    NotAnIndex {
        /// The part.
        part: String,
        /// The key.
        key: String,
    },
    /// An array index beyond the array.
    #[error("index {index} in `{key}` is out of range (length {len})")]
    OutOfRange {
        /// The index.
        index: usize,
        /// The key.
        key: String,
        /// The array's length.
        len: usize,
    },
    /// A part below a value that is neither a table nor an array.
    #[error("`{part}` in `{key}` is inside a value that is not a table")]
    NotATable {
        /// The part.
        part: String,
        /// The key.
        key: String,
    },
}

/// Sets the dotted `key` (array indices as numbers) of `root` to `value`, creating tables
/// on the way.
pub(super) fn set_path(
    root: &mut toml::Value,
    key: &str,
    value: toml::Value,
) -> Result<(), SetPathError> {
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err(SetPathError::BadKey {
            key: key.to_owned(),
        });
    }
    let mut cur = root;
    for (i, part) in parts.iter().enumerate() {
        let last = i + 1 == parts.len();
        cur = match cur {
            toml::Value::Table(t) => {
                if last {
                    t.insert((*part).to_owned(), value);
                    return Ok(());
                }
                t.entry((*part).to_owned())
                    .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            }
            toml::Value::Array(a) => {
                let index: usize = part.parse().map_err(|_| SetPathError::NotAnIndex {
                    part: (*part).to_owned(),
                    key: key.to_owned(),
                })?;
                let len = a.len();
                let slot = a.get_mut(index).ok_or_else(|| SetPathError::OutOfRange {
                    index,
                    key: key.to_owned(),
                    len,
                })?;
                if last {
                    *slot = value;
                    return Ok(());
                }
                slot
            }
            _ => {
                return Err(SetPathError::NotATable {
                    part: (*part).to_owned(),
                    key: key.to_owned(),
                })
            }
        };
    }
    Ok(())
}

/// 1-based line and column of byte offset `pos`.
pub fn line_col(text: &str, pos: usize) -> (usize, usize) {
    let before = text.get(..pos).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Best guess of the dotted key at byte offset `pos`: the last table header before it
/// (with its index for an array of tables, `agents[2]`) and the key on its line.
pub fn field_at(text: &str, pos: usize) -> String {
    let before = text.get(..pos).unwrap_or(text);
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line_end = text
        .get(pos..)
        .and_then(|r| r.find('\n'))
        .map_or(text.len(), |i| pos + i);
    let line = text.get(line_start..line_end).unwrap_or("").trim();
    // `[name]` → ("name", false); `[[name]]` → ("name", true).
    let header_of = |l: &str| -> Option<(String, bool)> {
        let l = l.trim();
        let array = l.starts_with("[[");
        let inner = l.strip_prefix('[')?.trim_start_matches('[');
        let end = inner.find(']')?;
        Some((inner.get(..end)?.trim().to_owned(), array))
    };
    let head = text.get(..line_end).unwrap_or("");
    let named = |name: &str, array: bool| -> String {
        if !array {
            return name.to_owned();
        }
        let count = head
            .lines()
            .filter(|l| header_of(l).is_some_and(|(n, a)| a && n == name))
            .count();
        format!("{name}[{}]", count.saturating_sub(1))
    };
    if let Some((h, array)) = header_of(line) {
        return named(&h, array);
    }
    let section = text
        .get(..line_start)
        .unwrap_or("")
        .lines()
        .rev()
        .find_map(header_of)
        .map(|(h, array)| named(&h, array))
        .unwrap_or_default();
    let key = line
        .split_once('=')
        .map(|(k, _)| k.trim().to_owned())
        .unwrap_or_default();
    match (section.is_empty(), key.is_empty()) {
        (true, _) => key,
        (false, true) => section,
        (false, false) => format!("{section}.{key}"),
    }
}

/// For serde's "unknown field `x`, expected one of `a`, `b`, …" (or "expected `a` or
/// `b`"): the expected name most like `x` (Jaro–Winkler similarity above 0.7, as clap's
/// suggestions), if there is one.
pub fn did_you_mean(message: &str) -> Option<String> {
    let rest = &message[message.find("unknown field `")? + "unknown field `".len()..];
    let name = &rest[..rest.find('`')?];
    let expected = &rest[rest.find("expected")?..];
    expected
        .split('`')
        .skip(1)
        .step_by(2)
        .map(|c| (strsim::jaro_winkler(name, c), c))
        .filter(|(score, _)| *score > 0.7)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, c)| c.to_owned())
}

/// Keys that were renamed: the old name, the new one, and what changed besides the name.
/// serde refuses the old name as an unknown field; [`renamed_key`] explains it.
pub const RENAMED_KEYS: &[(&str, &str, &str)] = &[
    (
        "bandwidth",
        "bandwidth_bps",
        "it is now in bits per second, the old key was bytes per second: multiply the old \
         value by 8 (bandwidth = 20000 → bandwidth_bps = 160000)",
    ),
    (
        "bit_rate",
        "bit_rate_bps",
        "same unit (bits per second), only the name changed",
    ),
];

/// For serde's "unknown field `x`, expected … `x_new` …" where `x` is a renamed key
/// ([`RENAMED_KEYS`]): the sentence that names the new key and the unit change.
pub fn renamed_key(message: &str) -> Option<String> {
    let (old, new, change) = RENAMED_KEYS.iter().find(|(old, new, _)| {
        message.contains(&format!("unknown field `{old}`")) && message.contains(&format!("`{new}`"))
    })?;
    Some(format!("`{old}` was renamed `{new}`: {change}"))
}

/// 1-based line of the header of the `k`-th (0-based) `[[table]]` entry in `text`, when
/// the array is written as headers (not inline).
pub fn array_entry_line(text: &str, table: &str, k: usize) -> Option<usize> {
    let header = format!("[[{table}]]");
    text.lines()
        .enumerate()
        .filter(|(_, l)| {
            let l = l.trim_start();
            l.starts_with(&header)
        })
        .nth(k)
        .map(|(i, _)| i + 1)
}

#[cfg(test)]
mod suggestion_tests {
    use super::*;

    #[test]
    fn the_nearest_expected_field_is_suggested() {
        let m = "unknown field `los`, expected one of `loss`, `latency`, `jitter`";
        assert_eq!(did_you_mean(m).as_deref(), Some("loss"));
        let m =
            "unknown field `stifness`, expected one of `stiffness`, `damping`, `estimator_gain`";
        assert_eq!(did_you_mean(m).as_deref(), Some("stiffness"));
        assert_eq!(
            did_you_mean("unknown field `zzzz`, expected `loss` or `mass`"),
            None
        );
        assert_eq!(did_you_mean("invalid type: string"), None);
    }

    #[test]
    fn a_renamed_key_names_its_new_name_and_unit() {
        let m = "unknown field `bandwidth`, expected one of `loss`, `bandwidth_bps`, `channel`";
        let r = renamed_key(m).unwrap();
        assert!(
            r.contains("`bandwidth_bps`") && r.contains("multiply"),
            "{r}"
        );
        // The same leaf name in another table (no `bandwidth_bps` expected) is not it.
        assert_eq!(
            renamed_key("unknown field `bandwidth`, expected `loss` or `mass`"),
            None
        );
    }

    #[test]
    fn array_entries_are_found_by_their_headers() {
        let t = "a = 1\n[[agents]]\nid = 1\n  [[agents]]\nid = 2\n[[triangles]]\n";
        assert_eq!(array_entry_line(t, "agents", 1), Some(4));
        assert_eq!(array_entry_line(t, "triangles", 0), Some(6));
        assert_eq!(array_entry_line(t, "triangles", 1), None);
    }
}
