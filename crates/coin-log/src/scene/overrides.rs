//! Changing a scene from the command line: `--set KEY=VALUE` edits the TOML table before it is read
//! (format.md: `--set`), then the explicit flags (`--duration`, `--rate`, ...) apply on top.

use super::file::{RecordFile, RunFile, SceneFile};
use super::SceneError;

/// Applies one `KEY=VALUE` to a scene table. KEY is a dotted path (`initial.steady.branch`); missing
/// tables on the way are created. VALUE is parsed as a TOML value (`0.3`, `[1, 2, 3]`, `"hoop"`,
/// `{ kind = "straight", omega_z = 1.0 }`), or taken as a bare string when it does not parse (`hoop`, `+`).
/// Refused without `=`, with an empty key part, or through a part of the path that is not a table.
///
/// ```
/// let mut t = toml::Table::new();
/// coin_log::scene::apply_set(&mut t, "run.rate=250").unwrap();
/// coin_log::scene::apply_set(&mut t, "body.shape=hoop").unwrap();
/// assert_eq!(t["run"]["rate"].as_integer(), Some(250));
/// assert_eq!(t["body"]["shape"].as_str(), Some("hoop"));
/// ```
pub fn apply_set(table: &mut toml::Table, arg: &str) -> Result<(), SceneError> {
    let Some((key, raw)) = arg.split_once('=') else {
        return Err(SceneError::Set {
            arg: arg.to_string(),
            reason: "expected KEY=VALUE, e.g. `--set initial.theta=0.4`".into(),
        });
    };
    set_value(table, key, parse_value(raw.trim())).map_err(|e| match e {
        SceneError::Set { reason, .. } => SceneError::Set {
            arg: crate::files::cut(arg, crate::files::SHOWN_CHARS).into_owned(),
            reason,
        },
        other => other,
    })
}

/// Sets the dotted KEY to a typed `value` (the form of [`apply_set`] for callers that hold TOML values,
/// such as `coin-log sweep`); missing tables on the way are created. The keys of the fact's other form
/// (`other_form`) are removed: `body.inertia_z = 0.4` on a scene with `body.shape` drops the shape.
///
/// ```
/// let mut t = toml::Table::new();
/// coin_log::scene::set_value(&mut t, "initial.omega", toml::Value::from(vec![0.0, 0.2, 1.5])).unwrap();
/// assert_eq!(t["initial"]["omega"].as_array().map(Vec::len), Some(3));
/// ```
pub fn set_value(table: &mut toml::Table, key: &str, value: toml::Value) -> Result<(), SceneError> {
    let error = |reason: String| SceneError::Set {
        arg: crate::files::cut(key, crate::files::SHOWN_CHARS).into_owned(),
        reason,
    };
    let key = key.trim();
    if !dotted(key) {
        return Err(error(format!(
            "`{key}` is not a dotted key like `run.rate` or `initial.steady.kind`"
        )));
    }
    let parts: Vec<&str> = key.split('.').map(str::trim).collect();
    // Tables nested as deep as the key would be dropped (and read) recursively: 60000 parts overflowed
    // the stack. No scene key has more than three.
    if parts.len() > MAX_KEY_PARTS {
        return Err(error(format!(
            "the key has {} dotted parts: a scene's keys have at most three, like `initial.steady.kind`",
            parts.len()
        )));
    }
    let (last, path) = parts
        .split_last()
        .ok_or_else(|| error("the key is empty".into()))?;
    let mut current = &mut *table;
    for (depth, part) in path.iter().enumerate() {
        let entry = current
            .entry((*part).to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        current = match entry {
            toml::Value::Table(t) => t,
            other => {
                return Err(error(format!(
                    "`{}` is {} = {}, not a table, so it has no key `{}`",
                    parts[..=depth].join("."),
                    other.type_str(),
                    other,
                    parts[depth + 1]
                )))
            }
        };
    }
    current.insert((*last).to_string(), value);
    for other in other_form(&parts.join(".")) {
        remove(table, other);
    }
    Ok(())
}

/// The most dotted parts a `--set` key may have: more than any scene key (three), far fewer than would
/// nest tables deep enough to overflow the stack.
const MAX_KEY_PARTS: usize = 16;

/// True for a dotted key with no empty part (`run.rate`, not `run..rate`).
pub(crate) fn dotted(key: &str) -> bool {
    key.split('.').all(|p| !p.trim().is_empty())
}

/// The keys that an edit of `key` removes: the other form of the same fact, which the scene may give one
/// way only (format.md: `--set`). A shape stands for both inertias, and a steady motion for θ and ω.
pub(crate) fn other_form(key: &str) -> &'static [&'static str] {
    match key {
        "body.shape" => &["body.inertia_x", "body.inertia_z"],
        "body.inertia_x" | "body.inertia_z" => &["body.shape"],
        "initial.theta" | "initial.omega" => &["initial.steady"],
        k if k == "initial.steady" || k.starts_with("initial.steady.") => {
            &["initial.theta", "initial.omega"]
        }
        _ => &[],
    }
}

/// Removes `key`, `table.name` as [`other_form`] gives them, where the table exists.
fn remove(table: &mut toml::Table, key: &str) {
    if let Some((name, last)) = key.split_once('.') {
        if let Some(toml::Value::Table(t)) = table.get_mut(name) {
            t.remove(last);
        }
    }
}

/// VALUE as TOML, else as a bare string.
fn parse_value(raw: &str) -> toml::Value {
    toml_value(raw).unwrap_or_else(|_| toml::Value::String(raw.to_string()))
}

/// VALUE as one TOML value, or why it is not one (the TOML reader's words).
fn toml_value(raw: &str) -> Result<toml::Value, String> {
    let mut table = toml::from_str::<toml::Table>(&format!("value = {raw}"))
        .map_err(|e| e.message().trim().to_string())?;
    match table.remove("value") {
        Some(value) if table.is_empty() => Ok(value),
        _ => Err("it is more than one value".into()),
    }
}

/// `error`, from reading a scene edited by `sets`, with a word on each VALUE that is not TOML and that the
/// error quotes as a string of the wrong type: `--set run.duration=1e400` is taken as the bare string
/// "1e400" (TOML's numbers end at 1.8e308), and serde's "invalid type: string" alone would not say why a
/// number became a string.
pub(crate) fn explain_bare_strings(error: SceneError, sets: &[String]) -> SceneError {
    let SceneError::Parse(message) = error else {
        return error;
    };
    let mut explained = message.clone();
    for set in sets {
        let Some((key, raw)) = set.split_once('=') else {
            continue;
        };
        let raw = raw.trim();
        let Err(reason) = toml_value(raw) else {
            continue;
        };
        // serde's words for a string where another type belongs: `invalid type: string "1e400"`. A word
        // (`fast`) says enough itself; a VALUE meant as a number or an array is told why it is none.
        if !message.contains(&format!("invalid type: string {raw:?}")) {
            continue;
        }
        let key = key.trim();
        let example = "e.g. a number 0.5 or 1e-3, an array [0.0, 0.2, 1.5]";
        if raw.is_empty() {
            explained.push_str(&format!(
                "; `--set {key}=` gives an empty value: write one after `=`, {example}"
            ));
        } else if raw.starts_with(|c: char| c.is_ascii_digit() || "+-.[{".contains(c)) {
            explained.push_str(&format!(
                "; `--set {key}={raw}`: `{raw}` is not a TOML value ({reason}), so it was taken as a bare \
                 string: write it as TOML, {example}"
            ));
        }
    }
    SceneError::Parse(explained)
}

/// The explicit `record` flags that override scene keys (applied after `--set`): `--<field>` (`-` for `_`)
/// sets `run.<field>`, `--channels` `record.channels` and `--rerun` `record.rerun = true`.
#[allow(missing_docs)]
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FlagOverrides {
    pub duration: Option<f64>,
    pub rate: Option<f64>,
    pub integrator: Option<String>,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    pub step: Option<f64>,
    pub max_steps: Option<u64>,
    pub channels: Option<Vec<String>>,
    pub rerun: bool,
}

impl FlagOverrides {
    /// The file with the flags applied, and which keys came from which flag.
    #[must_use]
    pub fn apply(&self, file: &SceneFile) -> (SceneFile, Vec<(&'static str, &'static str)>) {
        let mut file = file.clone();
        let mut provenance = Vec::new();
        let run = file.run.get_or_insert_with(RunFile::default);
        // `--flag` → `run.<field>`, the field of the same name in both.
        macro_rules! set {
            ($field:ident, $flag:literal) => {
                if self.$field.is_some() {
                    run.$field.clone_from(&self.$field);
                    provenance.push((concat!("run.", stringify!($field)), $flag));
                }
            };
        }
        set!(duration, "--duration");
        set!(rate, "--rate");
        set!(rtol, "--rtol");
        set!(atol, "--atol");
        set!(step, "--step");
        set!(max_steps, "--max-steps");
        set!(integrator, "--integrator");
        if let Some(channels) = &self.channels {
            file.record.get_or_insert_with(RecordFile::default).channels = Some(channels.clone());
            provenance.push(("record.channels", "--channels"));
        }
        if self.rerun {
            file.record.get_or_insert_with(RecordFile::default).rerun = Some(true);
            provenance.push(("record.rerun", "--rerun"));
        }
        (file, provenance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_that_are_not_toml_become_bare_strings() {
        assert_eq!(parse_value("+"), toml::Value::String("+".into()));
        assert_eq!(
            parse_value("thin-disk"),
            toml::Value::String("thin-disk".into())
        );
        assert_eq!(parse_value("1e-6"), toml::Value::Float(1e-6));
        assert_eq!(parse_value("\"+\""), toml::Value::String("+".into()));
        assert_eq!(
            parse_value("1\nx = 2"),
            toml::Value::String("1\nx = 2".into())
        );
    }

    #[test]
    fn a_set_through_a_value_is_refused_naming_the_value() {
        let mut t: toml::Table = toml::from_str("[body]\nmass = 1.0").unwrap();
        let e = apply_set(&mut t, "body.mass.x=1").unwrap_err().to_string();
        assert!(e.contains("`body.mass` is float"), "{e}");
        assert!(apply_set(&mut t, "run..rate=1").is_err());
        assert!(apply_set(&mut t, "run.rate").is_err());
    }

    #[test]
    fn an_edit_of_one_form_of_a_fact_removes_the_other() {
        let scene = "[body]\nmass = 1.0\nshape = \"thin-disk\"\n[initial]\ntheta = 0.5\nomega = [0.0, 0.0, 1.0]\nphi = 0.1\n";
        let keys = |t: &toml::Table, table: &str| -> Vec<String> {
            t[table].as_table().unwrap().keys().cloned().collect()
        };
        let mut t: toml::Table = toml::from_str(scene).unwrap();
        apply_set(&mut t, " body . inertia_z =0.4").unwrap();
        assert_eq!(keys(&t, "body"), ["inertia_z", "mass"]);
        apply_set(&mut t, "body.inertia_x=0.25").unwrap();
        apply_set(&mut t, "body.shape=hoop").unwrap();
        assert_eq!(keys(&t, "body"), ["mass", "shape"]);
        apply_set(&mut t, "initial.steady.kind=straight").unwrap();
        assert_eq!(keys(&t, "initial"), ["phi", "steady"]);
        apply_set(&mut t, "initial.theta=0.2").unwrap();
        assert_eq!(keys(&t, "initial"), ["phi", "theta"]);
        // Negative control: other keys of the same tables stay, and a file giving both forms is still
        // its author's contradiction, refused when read (scene::validate).
        apply_set(&mut t, "body.mass=2.0").unwrap();
        assert_eq!(keys(&t, "body"), ["mass", "shape"]);
        assert!(other_form("body.mass").is_empty() && other_form("initial.phi").is_empty());
    }
}
