//! Reading the TOML model file into names, specifications and expression strings, each
//! with its place in the file (spans from the `toml` crate).

use std::ops::Range;

use toml::de::{DeTable, DeValue};
use toml::Spanned;

use crate::ast::{is_identifier, is_reserved};
use crate::error::EquationError;
use crate::model::{InitialSpec, ParameterSpec, TimeDomain};

/// A name with the byte offset where the file writes it.
#[derive(Clone, Debug)]
pub struct Named {
    pub name: String,
    pub pos: usize,
}

/// An expression string with the means to map its offsets back into the file.
#[derive(Clone, Debug)]
pub struct ExprText {
    /// The key it is written under.
    pub key: Named,
    /// The expression.
    pub text: String,
    /// File offset of the first character of `text`.
    start: usize,
    /// Whether `text` appears verbatim in the file (no escapes), so that every offset maps.
    verbatim: bool,
}

impl ExprText {
    /// File offset of byte `k` of the expression (the string's start when escapes moved
    /// characters).
    pub fn file_offset(&self, k: usize) -> usize {
        if self.verbatim {
            self.start + k
        } else {
            self.start
        }
    }
}

/// Everything the file says, checked for form (not yet for the expressions).
#[derive(Clone, Debug)]
pub struct FileModel {
    pub name: String,
    pub time: TimeDomain,
    pub states: Vec<Named>,
    pub inputs: Vec<Named>,
    pub outputs: Vec<Named>,
    pub units: Vec<(String, String)>,
    pub parameters: Vec<(ParameterSpec, usize)>,
    pub initial: Vec<InitialSpec>,
    pub lets: Vec<ExprText>,
    pub equations: Vec<ExprText>,
    pub output: Vec<ExprText>,
    /// Where `[equations]` / `[output]` start (for a missing entry).
    pub equations_pos: usize,
    pub output_pos: usize,
}

type Table<'i> = DeTable<'i>;
type Value<'i> = Spanned<DeValue<'i>>;

struct Reader<'a> {
    text: &'a str,
}

impl Reader<'_> {
    fn err(&self, pos: usize, message: impl Into<String>) -> EquationError {
        EquationError::at(self.text, pos, message)
    }

    /// The entries of `table` in file order.
    fn entries<'t, 'i>(&self, table: &'t Table<'i>) -> Vec<(Named, &'t Value<'i>)> {
        let mut v: Vec<(Named, &Value)> = table
            .iter()
            .map(|(k, v)| {
                (
                    Named {
                        name: k.get_ref().to_string(),
                        pos: k.span().start,
                    },
                    v,
                )
            })
            .collect();
        v.sort_by_key(|(k, _)| k.pos);
        v
    }

    fn table<'t, 'i>(&self, v: &'t Value<'i>, what: &str) -> Result<&'t Table<'i>, EquationError> {
        v.get_ref().as_table().ok_or_else(|| {
            self.err(
                v.span().start,
                format!("{what} must be a table, not a {}", v.get_ref().type_str()),
            )
        })
    }

    fn string(&self, v: &Value, what: &str) -> Result<String, EquationError> {
        v.get_ref().as_str().map(str::to_string).ok_or_else(|| {
            self.err(
                v.span().start,
                format!("{what} must be a string, not a {}", v.get_ref().type_str()),
            )
        })
    }

    fn boolean(&self, v: &Value, what: &str) -> Result<bool, EquationError> {
        v.get_ref().as_bool().ok_or_else(|| {
            self.err(
                v.span().start,
                format!(
                    "{what} must be true or false, not a {}",
                    v.get_ref().type_str()
                ),
            )
        })
    }

    /// A number (integer or float); NaN is always refused, ±∞ unless `infinite_ok`.
    fn number(&self, v: &Value, what: &str, infinite_ok: bool) -> Result<f64, EquationError> {
        let pos = v.span().start;
        let x = match v.get_ref() {
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .map(|i| i as f64)
                .map_err(|_| self.err(pos, format!("bad number for {what}")))?,
            DeValue::Float(f) => f
                .as_str()
                .parse::<f64>()
                .map_err(|_| self.err(pos, format!("bad number for {what}")))?,
            other => {
                return Err(self.err(
                    pos,
                    format!("{what} must be a number, not a {}", other.type_str()),
                ))
            }
        };
        if x.is_nan() || (x.is_infinite() && !infinite_ok) {
            return Err(self.err(pos, format!("non-finite number {x} for {what}")));
        }
        Ok(x)
    }

    fn names(&self, v: &Value, what: &str) -> Result<Vec<Named>, EquationError> {
        let Some(items) = v.get_ref().as_array() else {
            return Err(self.err(
                v.span().start,
                format!("{what} must be an array of names like [\"x\", \"v\"]"),
            ));
        };
        items
            .iter()
            .map(|item| {
                // Point at the name, not at its opening quote.
                let start = item.span().start;
                let quoted = matches!(self.text.as_bytes().get(start), Some(b'"' | b'\''));
                Ok(Named {
                    name: self.string(item, what)?,
                    pos: start + usize::from(quoted),
                })
            })
            .collect()
    }

    /// An expression: a string, or a number taken as a constant expression.
    fn expr(&self, key: Named, v: &Value) -> Result<ExprText, EquationError> {
        let span: Range<usize> = v.span();
        match v.get_ref() {
            DeValue::String(s) => {
                let raw = &self.text[span.clone()];
                let mut prefix = if raw.starts_with("\"\"\"") || raw.starts_with("'''") {
                    3
                } else {
                    1
                };
                // A newline right after the opening of a multi-line string is dropped.
                if prefix == 3 {
                    if raw[3..].starts_with("\r\n") {
                        prefix += 2;
                    } else if raw[3..].starts_with('\n') {
                        prefix += 1;
                    }
                }
                let verbatim = raw.get(prefix..).is_some_and(|r| r.starts_with(s.as_ref()));
                Ok(ExprText {
                    key,
                    text: s.to_string(),
                    start: span.start + prefix.min(raw.len()),
                    verbatim,
                })
            }
            DeValue::Integer(_) | DeValue::Float(_) => {
                self.number(v, &format!("'{}'", key.name), false)?;
                Ok(ExprText {
                    key,
                    text: self.text[span.clone()].to_string(),
                    start: span.start,
                    verbatim: true,
                })
            }
            other => Err(self.err(
                span.start,
                format!(
                    "the expression for '{}' must be a string like \"k*x\", not a {}",
                    key.name,
                    other.type_str()
                ),
            )),
        }
    }

    fn unknown_key(&self, key: &Named, place: &str, allowed: &str) -> EquationError {
        self.err(
            key.pos,
            format!("unknown key '{}' in {place} (allowed: {allowed})", key.name),
        )
    }
}

/// Reads `text`.
pub fn read(text: &str) -> Result<FileModel, EquationError> {
    let r = Reader { text };
    let root = DeTable::parse(text).map_err(|e| {
        let pos = e.span().map_or(0, |s| s.start);
        r.err(pos, format!("TOML syntax: {}", e.message()))
    })?;
    let mut sections: [Option<(Named, &Value)>; 6] = Default::default();
    const SECTIONS: [&str; 6] = [
        "model",
        "parameters",
        "initial",
        "let",
        "equations",
        "output",
    ];
    for (key, v) in r.entries(root.get_ref()) {
        match SECTIONS.iter().position(|s| *s == key.name) {
            Some(i) => sections[i] = Some((key, v)),
            None => {
                return Err(r.unknown_key(
                    &key,
                    "the file",
                    "[model], [parameters], [initial], [let], [equations], [output]",
                ))
            }
        }
    }
    let [model, parameters, initial, lets, equations, output] = sections;
    let Some((_, model)) = model else {
        return Err(r.err(
            0,
            "missing [model] table (with name, states, inputs, outputs)",
        ));
    };
    let mut fm = read_model(&r, r.table(model, "[model]")?, model.span().start)?;
    if let Some((_, v)) = parameters {
        fm.parameters = read_parameters(&r, r.table(v, "[parameters]")?)?;
    }
    if let Some((_, v)) = initial {
        fm.initial = read_initial(&r, r.table(v, "[initial]")?, &fm.states)?;
    } else {
        fm.initial = default_initial(&fm.states);
    }
    if let Some((_, v)) = lets {
        fm.lets = read_exprs(&r, r.table(v, "[let]")?)?;
    }
    let Some((eq_key, equations)) = equations else {
        return Err(r.err(
            text.len(),
            "missing [equations] table: give one equation per state",
        ));
    };
    fm.equations = read_exprs(&r, r.table(equations, "[equations]")?)?;
    fm.equations_pos = eq_key.pos;
    let Some((out_key, output)) = output else {
        return Err(r.err(
            text.len(),
            "missing [output] table: give one expression per output",
        ));
    };
    fm.output = read_exprs(&r, r.table(output, "[output]")?)?;
    fm.output_pos = out_key.pos;
    check_names(&r, &fm)?;
    Ok(fm)
}

fn read_model(r: &Reader, t: &Table, pos: usize) -> Result<FileModel, EquationError> {
    let mut fm = FileModel {
        name: "model".into(),
        time: TimeDomain::Continuous,
        states: Vec::new(),
        inputs: Vec::new(),
        outputs: Vec::new(),
        units: Vec::new(),
        parameters: Vec::new(),
        initial: Vec::new(),
        lets: Vec::new(),
        equations: Vec::new(),
        output: Vec::new(),
        equations_pos: 0,
        output_pos: 0,
    };
    let mut units = None;
    let (mut have_states, mut have_outputs) = (false, false);
    for (key, v) in r.entries(t) {
        match key.name.as_str() {
            "name" => fm.name = r.string(v, "model name")?,
            "states" => {
                fm.states = r.names(v, "states")?;
                have_states = true;
            }
            "inputs" => fm.inputs = r.names(v, "inputs")?,
            "outputs" => {
                fm.outputs = r.names(v, "outputs")?;
                have_outputs = true;
            }
            "time" => {
                fm.time = match r.string(v, "time")?.as_str() {
                    "continuous" => TimeDomain::Continuous,
                    "discrete" => TimeDomain::Discrete,
                    other => {
                        return Err(r.err(
                            v.span().start,
                            format!(
                                "time = \"{other}\" is neither \"continuous\" nor \"discrete\""
                            ),
                        ))
                    }
                }
            }
            "units" => units = Some(v),
            _ => {
                return Err(r.unknown_key(
                    &key,
                    "[model]",
                    "name, states, inputs, outputs, time, units",
                ))
            }
        }
    }
    if !have_states || fm.states.is_empty() {
        return Err(r.err(pos, "[model] needs states = [\"x\", …] (at least one)"));
    }
    if !have_outputs || fm.outputs.is_empty() {
        return Err(r.err(pos, "[model] needs outputs = [\"y\", …] (at least one)"));
    }
    if let Some(v) = units {
        for (key, u) in r.entries(r.table(v, "units")?) {
            let known = fm
                .states
                .iter()
                .chain(&fm.inputs)
                .chain(&fm.outputs)
                .any(|n| n.name == key.name);
            if !known {
                return Err(r.err(
                    key.pos,
                    format!(
                        "unit for '{}', which is not a state, input or output (parameters carry their own unit)",
                        key.name
                    ),
                ));
            }
            fm.units.push((
                key.name.clone(),
                r.string(u, &format!("the unit of '{}'", key.name))?,
            ));
        }
    }
    Ok(fm)
}

fn read_parameters(r: &Reader, t: &Table) -> Result<Vec<(ParameterSpec, usize)>, EquationError> {
    let mut out = Vec::new();
    for (key, v) in r.entries(t) {
        let what = format!("parameter '{}'", key.name);
        let mut p = ParameterSpec {
            name: key.name.clone(),
            value: 0.0,
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            unit: String::new(),
            fixed: false,
        };
        let mut value_pos = v.span().start;
        let mut bound_pos = v.span().start;
        if let Some(spec) = v.get_ref().as_table() {
            let mut have_value = false;
            for (k, x) in r.entries(spec) {
                match k.name.as_str() {
                    "value" => {
                        p.value = r.number(x, &format!("the value of {what}"), false)?;
                        value_pos = x.span().start;
                        have_value = true;
                    }
                    "lower" => {
                        p.lower = r.number(x, &format!("the lower bound of {what}"), true)?;
                        bound_pos = x.span().start;
                    }
                    "upper" => {
                        p.upper = r.number(x, &format!("the upper bound of {what}"), true)?;
                        bound_pos = bound_pos.max(x.span().start);
                    }
                    "unit" => p.unit = r.string(x, &format!("the unit of {what}"))?,
                    "fixed" => p.fixed = r.boolean(x, &format!("'fixed' of {what}"))?,
                    _ => {
                        return Err(r.unknown_key(
                            &k,
                            &format!("[parameters] {}", key.name),
                            "value, lower, upper, unit, fixed",
                        ))
                    }
                }
            }
            if !have_value {
                return Err(r.err(key.pos, format!("{what} has no value (write value = …)")));
            }
        } else {
            p.value = r.number(v, &format!("the value of {what}"), false)?;
        }
        if p.lower > p.upper || p.lower == f64::INFINITY || p.upper == f64::NEG_INFINITY {
            return Err(r.err(
                bound_pos,
                format!(
                    "{what}: lower bound {} exceeds upper bound {} (or a bound is infinite on the wrong side)",
                    p.lower, p.upper
                ),
            ));
        }
        if p.value < p.lower || p.value > p.upper {
            return Err(r.err(
                value_pos,
                format!(
                    "{what}: value {} is outside its bounds [{}, {}]",
                    p.value, p.lower, p.upper
                ),
            ));
        }
        out.push((p, key.pos));
    }
    Ok(out)
}

fn default_initial(states: &[Named]) -> Vec<InitialSpec> {
    states
        .iter()
        .map(|s| InitialSpec {
            state: s.name.clone(),
            value: 0.0,
            fixed: true,
        })
        .collect()
}

fn read_initial(
    r: &Reader,
    t: &Table,
    states: &[Named],
) -> Result<Vec<InitialSpec>, EquationError> {
    let mut out = default_initial(states);
    for (key, v) in r.entries(t) {
        let Some(i) = states.iter().position(|s| s.name == key.name) else {
            return Err(r.err(
                key.pos,
                format!(
                    "initial value for '{}', which is not a state (states: {})",
                    key.name,
                    list(states)
                ),
            ));
        };
        let what = format!("the initial value of '{}'", key.name);
        if let Some(spec) = v.get_ref().as_table() {
            let mut have_value = false;
            for (k, x) in r.entries(spec) {
                match k.name.as_str() {
                    "value" => {
                        out[i].value = r.number(x, &what, false)?;
                        have_value = true;
                    }
                    "fixed" => out[i].fixed = r.boolean(x, &format!("'fixed' of {what}"))?,
                    _ => {
                        return Err(r.unknown_key(
                            &k,
                            &format!("[initial] {}", key.name),
                            "value, fixed",
                        ))
                    }
                }
            }
            if !have_value {
                return Err(r.err(key.pos, format!("{what} is missing (write value = …)")));
            }
        } else {
            out[i].value = r.number(v, &what, false)?;
        }
    }
    Ok(out)
}

fn read_exprs(r: &Reader, t: &Table) -> Result<Vec<ExprText>, EquationError> {
    r.entries(t)
        .into_iter()
        .map(|(key, v)| r.expr(key, v))
        .collect()
}

/// "x, v" for messages.
pub fn list(names: &[Named]) -> String {
    names
        .iter()
        .map(|n| n.name.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Every name is an identifier, not reserved and not used twice (outputs have their own
/// name space: an output may be called like the state it measures).
fn check_names(r: &Reader, fm: &FileModel) -> Result<(), EquationError> {
    let params: Vec<Named> = fm
        .parameters
        .iter()
        .map(|(p, pos)| Named {
            name: p.name.clone(),
            pos: *pos,
        })
        .collect();
    let lets: Vec<Named> = fm.lets.iter().map(|e| e.key.clone()).collect();
    let groups: [(&str, &[Named]); 4] = [
        ("a state", &fm.states),
        ("an input", &fm.inputs),
        ("a parameter", &params),
        ("a [let] quantity", &lets),
    ];
    let mut seen: Vec<(&str, &str)> = Vec::new();
    for (kind, names) in groups {
        for n in names {
            check_identifier(r, n)?;
            if let Some((_, first)) = seen.iter().find(|(s, _)| *s == n.name) {
                return Err(r.err(
                    n.pos,
                    format!("duplicate name '{}' (already {first})", n.name),
                ));
            }
            seen.push((&n.name, kind));
        }
    }
    for (i, n) in fm.outputs.iter().enumerate() {
        check_identifier(r, n)?;
        if fm.outputs[..i].iter().any(|o| o.name == n.name) {
            return Err(r.err(n.pos, format!("duplicate output name '{}'", n.name)));
        }
    }
    Ok(())
}

fn check_identifier(r: &Reader, n: &Named) -> Result<(), EquationError> {
    if !is_identifier(&n.name) {
        return Err(r.err(
            n.pos,
            format!(
                "'{}' is not a valid name (a letter or _, then letters, digits or _)",
                n.name
            ),
        ));
    }
    if is_reserved(&n.name) {
        return Err(r.err(
            n.pos,
            format!(
                "'{}' is a reserved word (t, pi, and, or, not and the function names); rename it",
                n.name
            ),
        ));
    }
    Ok(())
}
