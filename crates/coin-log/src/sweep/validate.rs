//! Sweep file → [`Sweep`]: every problem found at once, each with its key, the value and the fix
//! (format.md: Sweep files). A key is checked against the scene's keys and types by applying a value of
//! it to the base scene and reading the result as a scene file; whether the values give a *valid* scene
//! is each run's business (an invalid combination is a failed run, not a bad sweep file).

use super::catalogue::toml_text;
use super::definition::{
    Axis, Draw, Random, Settings, Sweep, CHANNELS_KEY, MAX_AXIS_VALUES, MAX_RUNS,
};
use super::file::{AxisFile, DrawFile, NormalFile, OutputFile, RandomFile, SweepFile};
use super::random::Distribution;
use super::space::{linspace, logspace};
use crate::files::shown_name;
use crate::format::Channel;
use crate::scene::{self, dotted, presets, ProblemCollector, SceneProblems};
use std::fmt::Display;
use std::path::Path;
use std::str::FromStr;

/// Values of a `values` axis or `choice` draw checked against the scene's types before running (the
/// rest are checked by their runs).
const CHECKED_VALUES: usize = 100;

/// Validates a parsed sweep file; `folder` is where a base scene path starts from.
pub(super) fn sweep(file: SweepFile, folder: &Path) -> Result<Sweep, SceneProblems> {
    let base = file.base.clone();
    checked(file, |c| c.base(&base, folder))
}

/// Validates a sweep file whose base scene is given as a table (a plan's, which holds it resolved).
pub(super) fn with_base(file: SweepFile, base: toml::Table) -> Result<Sweep, SceneProblems> {
    checked(file, |_| Some(base))
}

/// [`sweep`], the base scene read by `base` (`None`: it could not be, a problem noted).
fn checked(
    file: SweepFile,
    base: impl FnOnce(&mut Checker) -> Option<toml::Table>,
) -> Result<Sweep, SceneProblems> {
    let mut c = Checker {
        problems: ProblemCollector::new(&[]),
    };
    let base_table = base(&mut c);
    let places = places(&file);
    let set = c.set(&file.set);
    let parsed: Vec<Option<Axis>> = (file.axis.iter().enumerate())
        .map(|(i, a)| c.axis(i, a))
        .collect();
    let dimensions = c.dimensions(&parsed);
    let axes: Vec<Axis> = parsed.into_iter().flatten().collect();
    let random = file.random.as_ref().and_then(|r| c.random(r));
    let settings = c.settings(&file.output.unwrap_or_default());
    let mut sweep = Sweep {
        description: file.description.unwrap_or_default(),
        base: file.base,
        base_table: base_table.clone().unwrap_or_default(),
        set,
        axes,
        dimensions,
        random,
        settings,
    };
    c.collisions(&places);
    if c.problems.list.is_empty() {
        if let Some(base) = base_table {
            c.scene_keys(&sweep, &base, &places);
        }
        c.size(&sweep);
    }
    sweep.set.sort_by(|a, b| a.0.cmp(&b.0));
    SceneProblems::from_vec(c.problems.list).map_or(Ok(sweep), Err)
}

struct Checker {
    problems: ProblemCollector<'static>,
}

fn number(v: &toml::Value) -> Option<f64> {
    match v {
        #[allow(clippy::cast_precision_loss)] // a TOML integer used as a bound or an exponent
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(x) => Some(*x),
        _ => None,
    }
}

/// A whole number ≥ 0 (an integer, or a float with no fraction below 2⁵³).
fn whole(v: &toml::Value) -> Option<u64> {
    match v {
        toml::Value::Integer(i) => u64::try_from(*i).ok(),
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        // checked whole and in range
        toml::Value::Float(x) if x.fract() == 0.0 && (0.0..9e15).contains(x) => Some(*x as u64),
        _ => None,
    }
}

fn spec(values: Option<&Vec<toml::Value>>) -> &[toml::Value] {
    values.map_or(&[], Vec::as_slice)
}

fn axis_forms(a: &AxisFile) -> [(&'static str, bool); 3] {
    [
        ("values", a.values.is_some()),
        ("linspace", a.linspace.is_some()),
        ("logspace", a.logspace.is_some()),
    ]
}

/// A list as a problem shows it: TOML with its numbers in their shortest form (toml writes 1e308 with
/// 309 digits, which the problem's value then cut short).
fn array_text(values: &[toml::Value]) -> String {
    toml_text(&toml::Value::Array(values.to_vec()))
}

/// How problems name the fixed edit of `key`: `set."run.duration"`.
fn set_name(key: &str) -> String {
    format!("set.\"{key}\"")
}

impl Checker {
    /// The base scene as a table: a built-in by name, or a scene file by path.
    fn base(&mut self, base: &str, folder: &Path) -> Option<toml::Table> {
        let quoted = format!("\"{base}\"");
        if !presets::is_path(base) {
            if let Some(preset) = presets::preset(base) {
                return toml::Table::try_from(&preset).ok();
            }
            let names = presets::NAMES.join(", ");
            return self.problems.reject("base", quoted, format!(
                "is no built-in scene ({names}) and not a path: a scene file is given by its path relative \
                 to the sweep file, such as \"./{base}.toml\""));
        }
        let path = folder.join(base);
        let text = match crate::files::read_toml(&path, crate::files::InputKind::Scene) {
            Ok(text) => text,
            Err(e) => {
                return self.problems.reject("base", quoted, format!(
                    "cannot be read ({e}; looked for `{}`): give the path of a scene file relative to the \
                     sweep file", path.display()));
            }
        };
        match toml::from_str::<toml::Table>(&text) {
            Ok(table) => Some(table),
            Err(e) => {
                let message = scene::toml_message(&e).replace('\n', " ");
                self.problems.reject(
                    "base",
                    quoted,
                    format!("is not a TOML scene file: {message}"),
                )
            }
        }
    }

    fn set(&mut self, set: &toml::Table) -> Vec<(String, toml::Value)> {
        let mut edits = Vec::new();
        for (key, value) in set {
            if !dotted(key) {
                self.problems.push(
                    set_name(key),
                    toml_text(value),
                    "is not a dotted scene key like \"run.duration\"",
                );
            } else if let (Some(inner), false) = (value.as_table(), key.contains('.')) {
                let example = inner.iter().next().map_or_else(
                    || format!("\"{key}.name\" = value"),
                    |(k, v)| format!("\"{key}.{k}\" = {v}"),
                );
                self.problems.push(
                    format!("set.{key}"),
                    toml_text(value),
                    format!(
                        "is a table: TOML reads an unquoted dotted key as nested tables, which would \
                         replace the whole `{key}` table; quote the key so that it names one scene key: \
                         set = {{ {example} }}"
                    ),
                );
            } else {
                edits.push((key.clone(), value.clone()));
            }
        }
        edits
    }

    /// Notes `{name}.key` unless `key` is dotted like `example`.
    fn key(&mut self, name: &str, key: &str, example: &str) {
        if !dotted(key) {
            self.problems.push(
                format!("{name}.key"),
                format!("\"{key}\""),
                format!("is not a dotted scene key like \"{example}\""),
            );
        }
    }

    /// The one of `forms` (name, given) that is given at `name`; else notes `none`, or that several are.
    fn form(
        &mut self,
        name: &str,
        forms: &[(&'static str, bool)],
        none: &str,
        one: &str,
    ) -> Option<&'static str> {
        let given: Vec<&str> = forms
            .iter()
            .filter_map(|&(n, on)| on.then_some(n))
            .collect();
        match given.as_slice() {
            [form] => Some(form),
            [] => self.problems.reject(name, "", none),
            several => self.problems.reject(
                name,
                "",
                format!("gives {}: give exactly one {one}", several.join(" and ")),
            ),
        }
    }

    fn axis(&mut self, i: usize, a: &AxisFile) -> Option<Axis> {
        let name = format!("axis[{i}]");
        self.key(&name, &a.key, "initial.theta");
        if a.zip.as_deref().is_some_and(|z| z.trim().is_empty()) {
            self.problems.push(
                format!("{name}.zip"),
                "\"\"",
                "is empty: give the zip group a name",
            );
        }
        let form = self.form(&name, &axis_forms(a), "has no values: give one of `values = [...]`, `linspace = [first, last, n]` or `logspace = [first_exp, last_exp, n]`", "of them")?;
        let at = format!("{name}.{form}");
        let values = match form {
            "values" => self.listed(&at, spec(a.values.as_ref())),
            "linspace" => self.spaced(&at, spec(a.linspace.as_ref()), linspace,
                "first·(n − 1 − k) + last·k overflows: keep |first|·(n − 1) and |last|·(n − 1) below about 1.8e308"),
            _ => self.spaced(&at, spec(a.logspace.as_ref()), logspace,
                "keep the exponents within ±300"),
        }?;
        Some(Axis {
            key: a.key.trim().to_string(),
            values,
            zip: a.zip.clone(),
        })
    }

    fn listed(&mut self, name: &str, values: &[toml::Value]) -> Option<Vec<toml::Value>> {
        if values.is_empty() {
            return self
                .problems
                .reject(name, "[]", "is empty: give at least one value");
        }
        // A string is its cell as it is: a line break would split the run's row, which the journal and
        // the parts hold one to a line (resume redid such a run every time, collect refused its part).
        let broken = values
            .iter()
            .filter_map(toml::Value::as_str)
            .find(|s| s.contains(['\n', '\r']));
        if let Some(value) = broken {
            return self.problems.reject(
                name,
                format!("{value:?}"),
                "holds a line break, which no scene key takes and a catalogue row (one line) cannot hold: remove it",
            );
        }
        Some(values.to_vec())
    }

    /// `[first, last, n]` through `space` (linspace or logspace of the exponents).
    fn spaced(
        &mut self,
        name: &str,
        spec: &[toml::Value],
        space: fn(f64, f64, u64) -> Vec<f64>,
        overflow: &str,
    ) -> Option<Vec<toml::Value>> {
        let text = array_text(spec);
        let [first, last, n] = spec else {
            return self.problems.reject(
                name,
                text,
                "must be [first, last, n]: two numbers and a count",
            );
        };
        let ends = [first, last].map(|v| number(v).filter(|x| x.is_finite()));
        let n = whole(n).filter(|&n| n >= 1);
        let (Some(first), Some(last)) = (ends[0], ends[1]) else {
            return self.problems.reject(
                name,
                text,
                "must start with two finite numbers, [first, last, n]",
            );
        };
        let Some(n) = n.filter(|&n| n <= MAX_AXIS_VALUES) else {
            return self.problems.reject(name, text, format!(
                "must end with a whole number of values n, 1 ≤ n ≤ {MAX_AXIS_VALUES} (more samples of a key: draw it, [[random.draw]])"));
        };
        let values: Vec<f64> = space(first, last, n);
        if let Some(bad) = values.iter().find(|x| !x.is_finite()) {
            return self
                .problems
                .reject(name, text, format!("gives {bad}: {overflow}"));
        }
        Some(values.into_iter().map(toml::Value::Float).collect())
    }

    /// The grid's dimensions: each axis alone, or with the axes sharing its zip name, placed at the first
    /// (indexes of the file's axes; those that had a problem are left out, and then the sweep is refused).
    fn dimensions(&mut self, axes: &[Option<Axis>]) -> Vec<Vec<usize>> {
        let mut dimensions: Vec<Vec<usize>> = Vec::new();
        for (i, axis) in axes.iter().enumerate() {
            let Some(axis) = axis else { continue };
            let zip = axis.zip.as_ref();
            let group = zip.and_then(|z| {
                dimensions
                    .iter_mut()
                    .find(|d| axes[d[0]].as_ref().and_then(|a| a.zip.as_ref()) == Some(z))
            });
            let Some(group) = group else {
                dimensions.push(vec![i]);
                continue;
            };
            let first = group[0];
            let len = axes[first].as_ref().map_or(0, |a| a.values.len());
            if len != axis.values.len() {
                self.problems.push(
                    format!("axis[{i}].zip"),
                    format!("\"{}\"", zip.map_or("", String::as_str)),
                    format!(
                        "zips axes of different lengths (axis[{first}] has {len}, axis[{i}] has {} values): \
                         zipped axes vary together, so give each as many values",
                        axis.values.len()
                    ),
                );
            }
            group.push(i);
        }
        dimensions
    }

    fn random(&mut self, r: &RandomFile) -> Option<Random> {
        let seed = whole(&r.seed).filter(|&s| i64::try_from(s).is_ok());
        if seed.is_none() {
            self.problems.push(
                "random.seed",
                toml_text(&r.seed),
                // A whole float within the range (9e15) was refused with the range alone.
                if r.seed.is_float() {
                    "must be a whole number from 0 to 9223372036854775807, written as an integer (a \
                     float is taken only below 9e15, where doubles hold every whole number)"
                } else {
                    "must be a whole number from 0 to 9223372036854775807"
                },
            );
        }
        let count = whole(&r.count).filter(|&c| (1..=MAX_RUNS).contains(&c));
        if count.is_none() {
            self.problems.push(
                "random.count",
                toml_text(&r.count),
                format!("must be a whole number of runs per grid point, 1 … {MAX_RUNS}"),
            );
        }
        if r.draw.is_empty() {
            self.problems.push("random.draw", "", "has no draws: add a [[random.draw]] with a key and a distribution, or remove [random]");
        }
        let draws: Vec<Draw> = r
            .draw
            .iter()
            .enumerate()
            .filter_map(|(j, d)| self.draw(j, d))
            .collect();
        (draws.len() == r.draw.len()).then_some(Random {
            seed: seed?,
            count: count?,
            draws,
        })
    }

    fn draw(&mut self, j: usize, d: &DrawFile) -> Option<Draw> {
        let name = format!("random.draw[{j}]");
        self.key(&name, &d.key, "body.friction");
        let forms = [
            ("uniform", d.uniform.is_some()),
            ("log_uniform", d.log_uniform.is_some()),
            ("normal", d.normal.is_some()),
            ("choice", d.choice.is_some()),
        ];
        let form = self.form(&name, &forms, "has no distribution: give one of `uniform = [lo, hi]`, `log_uniform = [lo, hi]`, `normal = { mean, std, min, max }` or `choice = [...]`", "distribution")?;
        let at = format!("{name}.{form}");
        let distribution = match form {
            "uniform" => self.bounds(&at, spec(d.uniform.as_ref()), false),
            "log_uniform" => self.bounds(&at, spec(d.log_uniform.as_ref()), true),
            "normal" => self.normal(&at, d.normal.as_ref()?),
            _ => self
                .listed(&at, spec(d.choice.as_ref()))
                .map(|choices| Distribution::Choice { len: choices.len() }),
        }?;
        Some(Draw {
            key: d.key.trim().to_string(),
            distribution,
            // Empty but for a choice draw: only one form is given.
            choices: d.choice.clone().unwrap_or_default(),
        })
    }

    /// `[lo, hi]` of a uniform (or, `log`, log-uniform) draw.
    fn bounds(&mut self, name: &str, spec: &[toml::Value], log: bool) -> Option<Distribution> {
        let pair = match spec {
            [lo, hi] => number(lo).zip(number(hi)),
            _ => None,
        };
        let ok = |(lo, hi): (f64, f64)| {
            lo.is_finite() && hi.is_finite() && lo < hi && (!log || lo > 0.0)
        };
        match pair.filter(|&p| ok(p)) {
            Some((lo, hi)) if log => Some(Distribution::LogUniform { lo, hi }),
            // lo + (hi − lo)·u is inf for every u when the width overflows.
            Some((lo, hi)) if (hi - lo).is_infinite() => self.problems.reject(
                name,
                array_text(spec),
                "is wider than the largest double (hi − lo overflows, so every draw would be inf): narrow it, or draw log_uniform",
            ),
            Some((lo, hi)) => Some(Distribution::Uniform { lo, hi }),
            None => {
                let need = if log { "0 < lo < hi" } else { "lo < hi" };
                self.problems.reject(
                    name,
                    array_text(spec),
                    format!("must be [lo, hi], two finite numbers with {need}"),
                )
            }
        }
    }

    fn normal(&mut self, name: &str, n: &NormalFile) -> Option<Distribution> {
        // Each value is held to what its message says it must be (an infinite mean once passed, and was
        // then dropped without a word, and the whole [random] table with it).
        let mut value = |key: &str, v: &toml::Value, need: &str, ok: fn(f64) -> bool| {
            number(v).filter(|&x| ok(x)).or_else(|| {
                let key = format!("{name}.{key}");
                self.problems
                    .reject(key, toml_text(v), format!("must be {need}"))
            })
        };
        let mean = value("mean", &n.mean, "a finite number", f64::is_finite);
        let std = value("std", &n.std, "a finite number > 0", |x| {
            x.is_finite() && x > 0.0
        });
        let mut bound = |key, v: Option<&toml::Value>, default| {
            v.map_or(Some(default), |v| {
                value(key, v, "a number", |x| !x.is_nan())
            })
        };
        let min = bound("min", n.min.as_ref(), f64::NEG_INFINITY);
        let max = bound("max", n.max.as_ref(), f64::INFINITY);
        let (mean, std, min, max) = (mean?, std?, min?, max?);
        if min >= max {
            return self.problems.reject(
                name,
                format!(
                    "{{ min = {}, max = {} }}",
                    toml_text(&min.into()),
                    toml_text(&max.into())
                ),
                "has min ≥ max: give min < max",
            );
        }
        Some(Distribution::Normal {
            mean,
            std,
            min,
            max,
        })
    }

    fn settings(&mut self, o: &OutputFile) -> Settings {
        let encoding = self.named("encoding", o.encoding.as_deref());
        let compression = self.named("compression", o.compression.as_deref());
        let channels: Option<Vec<String>> =
            (o.channels.as_ref()).map(|l| l.iter().map(|c| c.trim().to_string()).collect());
        let given = o.channels.iter().flatten().zip(channels.iter().flatten());
        for (i, (c, trimmed)) in given.enumerate() {
            if let Err(e) = trimmed.parse::<Channel>() {
                self.problems
                    .push("output.channels", format!("\"{c}\""), e.to_string());
            }
            // Fixed for every run, so a list the scene refuses would fail them all: said here.
            if channels.iter().flatten().take(i).any(|l| l == trimmed) {
                self.problems.push(
                    "output.channels",
                    format!("\"{c}\""),
                    "is listed twice: list each channel once",
                );
            }
        }
        if o.channels.as_ref().is_some_and(Vec::is_empty) {
            self.problems.push(
                "output.channels",
                "[]",
                "is empty: list at least one channel, or leave the key out for the scenes' lists",
            );
        }
        Settings {
            channels,
            encoding,
            compression,
            verify: o.verify.unwrap_or(true),
            predict: o.predict.unwrap_or(true),
        }
    }

    /// `output.{key}` by its name, or (none given, or a wrong name noted) the default.
    fn named<T: FromStr + Default>(&mut self, key: &str, name: Option<&str>) -> T
    where
        T::Err: Display,
    {
        let Some(name) = name else {
            return T::default();
        };
        name.parse().unwrap_or_else(|e: T::Err| {
            self.problems.push(
                format!("output.{key}"),
                format!("\"{name}\""),
                e.to_string(),
            );
            T::default()
        })
    }
}

/// Every key the sweep writes, in the order the edits apply, with where it is given and what is checked
/// against the scene: `set` (sorted), the axes, the draws, `output.channels`.
struct Place {
    key: String,
    /// `set."run.duration"`, `axis[0]`, `random.draw[1]`, `output.channels`.
    name: String,
    /// The key holding the values (`axis[0].values`), for problems with a value.
    values_name: String,
}

impl Place {
    /// How a problem with the key names it: `axis[0].key` = "initial.theta", `set."run"` (the key is the
    /// name), or `output.channels`, saying which key it sets.
    fn key_problem(&self, reason: &str) -> (String, String, String) {
        if self.name.ends_with(']') {
            let value = format!("\"{}\"", self.key);
            (format!("{}.key", self.name), value, reason.to_string())
        } else if self.name.starts_with("set.") {
            (self.name.clone(), String::new(), reason.to_string())
        } else {
            let reason = format!("sets `{}`, which {reason}", self.key);
            (self.name.clone(), String::new(), reason)
        }
    }

    /// A place whose values are given at `name` itself.
    fn new(key: &str, name: String) -> Self {
        Self {
            key: key.trim().to_string(),
            values_name: name.clone(),
            name,
        }
    }
}

fn places(file: &SweepFile) -> Vec<Place> {
    let mut places: Vec<Place> = file
        .set
        .keys()
        .map(|k| Place::new(k, set_name(k)))
        .collect();
    for (i, a) in file.axis.iter().enumerate() {
        let form = axis_forms(a)
            .into_iter()
            .find_map(|(n, on)| on.then_some(n))
            .unwrap_or("values");
        places.push(Place {
            values_name: format!("axis[{i}].{form}"),
            ..Place::new(&a.key, format!("axis[{i}]"))
        });
    }
    for (j, d) in file.random.iter().flat_map(|r| r.draw.iter().enumerate()) {
        places.push(Place::new(&d.key, format!("random.draw[{j}]")));
    }
    if file.output.as_ref().is_some_and(|o| o.channels.is_some()) {
        places.push(Place::new(CHANNELS_KEY, "output.channels".to_string()));
    }
    places
}

impl Checker {
    /// A key given twice, a key inside a table that a later edit replaces, or one a later edit removes as
    /// the other form of its fact ([`scene::other_form`]).
    fn collisions(&mut self, places: &[Place]) {
        for (later_at, later) in places.iter().enumerate() {
            for earlier in &places[..later_at] {
                let reason = if earlier.key == later.key {
                    format!(
                        "is also given by {}: each key is set or swept in one place only",
                        earlier.name
                    )
                } else if earlier.key.starts_with(&format!("{}.", later.key)) {
                    format!(
                        "replaces the whole table holding `{}` (given by {}, which applies first): give that key \
                         inside {}'s values, or sweep a key inside `{}`",
                        shown_name(&earlier.key),
                        earlier.name,
                        later.name,
                        shown_name(&later.key)
                    )
                } else if scene::other_form(&later.key).contains(&earlier.key.as_str()) {
                    format!(
                        "removes `{}` (given by {}, which applies first), the other form of the same fact: \
                         give one form only",
                        shown_name(&earlier.key),
                        earlier.name
                    )
                } else {
                    continue;
                };
                let (name, value, reason) = later.key_problem(&reason);
                self.problems.push(name, value, reason);
            }
        }
    }

    /// Each key's values against the scene's keys and types, on the base scene with `set` applied.
    fn scene_keys(&mut self, sweep: &Sweep, base: &toml::Table, places: &[Place]) {
        let fits = |table: &toml::Table, key: &str, value: &toml::Value| -> Result<(), String> {
            let mut table = table.clone();
            scene::set_value(&mut table, key, value.clone()).map_err(|e| e.to_string())?;
            scene::file_from_table(table)
                .map(drop)
                .map_err(|e| e.to_string())
        };
        let mut with_set = base.clone();
        for (key, value) in &sweep.set {
            if let Err(e) = fits(base, key, value) {
                self.problems.push(
                    set_name(key),
                    toml_text(value),
                    format!("does not fit the scene: {e}"),
                );
            }
            let _ = scene::set_value(&mut with_set, key, value.clone());
        }
        if !self.problems.list.is_empty() {
            return;
        }
        if let Err(e) = scene::file_from_table(with_set.clone()) {
            self.problems
                .push("set", "", format!("does not fit the scene: {e}"));
            return;
        }
        let draws = sweep.random.iter().flat_map(|r| &r.draws);
        let candidates = sweep
            .axes
            .iter()
            .map(|a| a.values.clone())
            .chain(draws.map(representatives));
        let channels = sweep.settings.channels.as_ref();
        let channels = channels.map(|l| vec![toml::Value::from(l.clone())]);
        let swept = places.iter().filter(|p| !p.name.starts_with("set."));
        for (place, values) in swept.zip(candidates.chain(channels)) {
            for value in values.iter().take(CHECKED_VALUES) {
                if let Err(e) = fits(&with_set, &place.key, value) {
                    self.problems.push(
                        place.values_name.clone(),
                        toml_text(value),
                        format!(
                            "does not fit the scene key `{}`: {e}",
                            shown_name(&place.key)
                        ),
                    );
                    break;
                }
            }
        }
    }

    /// At most [`MAX_RUNS`] runs and [`MAX_AXIS_VALUES`] axis values.
    fn size(&mut self, sweep: &Sweep) {
        let values: usize = sweep.axes.iter().map(|a| a.values.len()).sum();
        if values as u64 > MAX_AXIS_VALUES {
            self.problems.push("axis", "", format!(
                "gives {values} values in all, more than the {MAX_AXIS_VALUES} the axes may (sweep.json lists them): \
                 draw the densest keys at random ([[random.draw]]), or split the sweep"));
        }
        let text =
            |n: Option<u64>| n.map_or_else(|| "more than 2⁶⁴".to_string(), |n| n.to_string());
        let points = sweep.lengths().try_fold(1u64, u64::checked_mul);
        let runs = points.and_then(|p| p.checked_mul(sweep.per_point()));
        // The grid alone, or `random.count` runs at each of its points: the problem names the factor
        // that makes them too many (the axes were once blamed for the count's runs).
        match points {
            Some(points) if points <= MAX_RUNS => {
                if runs.is_none_or(|r| r > MAX_RUNS) {
                    self.problems.push(
                        "random.count",
                        sweep.per_point().to_string(),
                        format!(
                            "runs at each of the axes' {points} grid points give {} runs, more than the \
                             {MAX_RUNS} a sweep may have: draw fewer runs per point, sweep fewer values, \
                             or split the sweep",
                            text(runs)
                        ),
                    );
                }
            }
            _ => self.problems.push("axis", "", format!(
                "gives {} grid points, each a run at least, more than the {MAX_RUNS} runs a sweep may have: \
                 sweep fewer values, or split the sweep",
                text(points))),
        }
    }
}

/// Values of a draw that show whether its key takes them: the lower bound or the mean, or the choices.
fn representatives(d: &Draw) -> Vec<toml::Value> {
    match d.distribution {
        Distribution::Uniform { lo, .. } | Distribution::LogUniform { lo, .. } => {
            vec![toml::Value::Float(lo)]
        }
        Distribution::Normal { mean, .. } => vec![toml::Value::Float(mean)],
        Distribution::Choice { .. } => d.choices.clone(),
    }
}
