//! `--set TABLE.KEY=VALUE` scene overrides: dotted keys applied to a
//! scene's TOML document before it is deserialised and validated, so an
//! overridden value passes exactly the checks a value in the file does, and
//! an error names the key given on the command line, what was wrong and
//! what is allowed.
//!
//! A key is a dotted path of TOML keys, each optionally indexed into an
//! array of tables: `render.slices.quality`, `ellipsoids[1].strength`,
//! `render.slices.tiers[0].media`. A value is TOML (`64`, `0.5`, `true`,
//! `[1.0, 0.9, 0.8]`, `"wispy"`); a bare word that is not TOML is taken as
//! a string, so `render.slices.tiers[0].media=wispy` works unquoted.

use std::path::Path;

use super::{SceneProfile, locate};
use crate::error::{Error, Result};

/// One parsed `--set` argument.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    /// The dotted key as given.
    pub key: String,
    /// The value as given.
    pub raw: String,
    /// The key's parts: a name and an optional array index each.
    path: Vec<(String, Option<usize>)>,
    value: toml::Value,
}

fn bad_key(arg: &str, why: &str) -> Error {
    Error::invalid(
        "--set",
        arg,
        format!(
            "{why}; expected TABLE.KEY=VALUE, e.g. render.slices.quality=64 or ellipsoids[0].strength=0.5"
        ),
    )
}

impl Override {
    /// Parses `TABLE.KEY=VALUE`.
    pub fn parse(arg: &str) -> Result<Self> {
        let (key, raw) = arg.split_once('=').ok_or_else(|| bad_key(arg, "no '='"))?;
        let (key, raw) = (key.trim(), raw.trim());
        let mut path = Vec::new();
        for part in key.split('.') {
            let (name, index) = match part.strip_suffix(']').and_then(|p| p.split_once('[')) {
                Some((name, i)) => {
                    let i = i
                        .parse::<usize>()
                        .map_err(|_| bad_key(arg, &format!("index [{i}] is not a whole number")))?;
                    (name, Some(i))
                }
                None => (part, None),
            };
            if name.is_empty()
                || !name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
            {
                return Err(bad_key(
                    arg,
                    &format!(
                        "'{part}' is not a key (letters, digits, '_', '-', then an optional [index])"
                    ),
                ));
            }
            path.push((name.to_string(), index));
        }
        if raw.is_empty() {
            return Err(bad_key(arg, "no value after '='"));
        }
        let value = toml::from_str::<toml::Table>(&format!("v = {raw}"))
            .ok()
            .and_then(|mut t| t.remove("v"))
            .unwrap_or_else(|| toml::Value::String(raw.to_string()));
        Ok(Self {
            key: key.to_string(),
            raw: raw.to_string(),
            path,
            value,
        })
    }

    fn error(&self, allowed: impl Into<String>) -> Error {
        Error::invalid(format!("--set {}", self.key), &self.raw, allowed)
    }

    /// Writes the value into `doc`, creating missing tables on the way; an
    /// array index must name an existing element.
    pub fn apply(&self, doc: &mut toml::Table) -> Result<()> {
        let mut table = doc;
        let last = self.path.len() - 1;
        for (depth, (name, index)) in self.path.iter().enumerate() {
            let here = self.path[..=depth]
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(".");
            if depth == last && index.is_none() {
                table.insert(name.clone(), self.value.clone());
                return Ok(());
            }
            let entry = table
                .entry(name.clone())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            let slot = match index {
                Some(i) => {
                    let toml::Value::Array(items) = entry else {
                        return Err(
                            self.error(format!("`{here}` is not an array, so it takes no [index]"))
                        );
                    };
                    let len = items.len();
                    items.get_mut(*i).ok_or_else(|| {
                        self.error(format!(
                            "`{here}` has {len} entries (index 0 to {})",
                            len as i64 - 1
                        ))
                    })?
                }
                None => entry,
            };
            if depth == last {
                *slot = self.value.clone();
                return Ok(());
            }
            let toml::Value::Table(next) = slot else {
                return Err(self.error(format!("`{here}` is a value, not a table")));
            };
            table = next;
        }
        Ok(())
    }

    /// Whether a validation error about parameter `name` concerns this key
    /// (the key itself, a part of it, or the table it sets).
    fn concerns(&self, name: &str) -> bool {
        let within = |a: &str, b: &str| {
            a == b || a.starts_with(&format!("{b}.")) || a.starts_with(&format!("{b}["))
        };
        within(name, &self.key) || within(&self.key, name)
    }
}

/// Parses `text` (from `path`), applies `overrides` in order and validates
/// the result. Errors in the file name its line and column as
/// [`SceneProfile::load`] does; errors an override causes name `--set KEY`,
/// the value given and what is allowed.
pub fn load_with_overrides(text: &str, path: &Path, overrides: &[String]) -> Result<SceneProfile> {
    let mut profile = SceneProfile::from_toml(text, path)?;
    let parsed = overrides
        .iter()
        .map(|o| Override::parse(o))
        .collect::<Result<Vec<_>>>()?;
    if !parsed.is_empty() {
        let mut doc: toml::Table =
            toml::from_str(text).map_err(|e| Error::parse(path, 0, 0, e.message().to_string()))?;
        for o in &parsed {
            o.apply(&mut doc)?;
            // Deserialise after each override, so a type error or an
            // unknown key is pinned on the override that caused it.
            profile = doc
                .clone()
                .try_into()
                .map_err(|e: toml::de::Error| o.error(e.message().trim().to_string()))?;
        }
    }
    profile.validate().map_err(|e| match e {
        Error::InvalidParameter {
            name,
            value,
            allowed,
        } => match parsed.iter().rev().find(|o| o.concerns(&name)) {
            Some(o) if o.key == name => o.error(allowed),
            Some(o) => o.error(format!("{name} = {value}: {allowed}")),
            None => locate(
                Error::InvalidParameter {
                    name,
                    value,
                    allowed,
                },
                text,
                path,
            ),
        },
        other => other,
    })?;
    Ok(profile)
}
