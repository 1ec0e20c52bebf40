//! Parser of `.lsys` grammar files (format in the module docs of [`super`]).

use super::expr::{Expr, ExprParser, Scope};
use super::{Grammar, GrammarError, Production};
use crate::limits::Limits;
use crate::model::WoodProperties;
use glam::DVec3;
use std::collections::HashMap;

struct Consts<'a>(&'a HashMap<String, f64>);
impl Scope for Consts<'_> {
    fn resolve(&self, name: &str) -> Option<Result<f64, u16>> {
        self.0.get(name).map(|v| Ok(*v))
    }
}

struct Params<'a> {
    names: &'a [String],
    consts: &'a HashMap<String, f64>,
}
impl Scope for Params<'_> {
    fn resolve(&self, name: &str) -> Option<Result<f64, u16>> {
        if let Some(i) = self.names.iter().position(|n| n == name) {
            return Some(Err(i as u16));
        }
        self.consts.get(name).map(|v| Ok(*v))
    }
}

/// Allowed parameter counts of the turtle symbols.
fn turtle_arity(sym: u8) -> Option<(usize, usize, &'static str)> {
    Some(match sym {
        b'F' | b'f' => (0, 1, "a length"),
        b'+' | b'-' | b'&' | b'^' | b'\\' | b'/' => (0, 1, "an angle in degrees"),
        b'|' | b'$' | b'[' | b']' => (0, 0, "no parameters"),
        b'!' => (1, 1, "a width, e.g. !(0.5)"),
        b'~' => (0, 2, "a length and a width"),
        _ => return None,
    })
}

fn strip_comment(line: &str) -> &str {
    let mut end = line.len();
    if let Some(i) = line.find('#') {
        end = end.min(i);
    }
    if let Some(i) = line.find("//") {
        end = end.min(i);
    }
    &line[..end]
}

struct Ctx<'a> {
    file: &'a str,
    line: usize,
    max_depth: usize,
}

impl Ctx<'_> {
    fn parser<'s, S: Scope>(&'s self, text: &'s str, col0: usize, scope: &'s S) -> ExprParser<'s, S> {
        ExprParser {
            src: text.as_bytes(),
            pos: 0,
            file: self.file,
            line: self.line,
            col0,
            scope,
            depth: 0,
            max_depth: self.max_depth,
        }
    }

    fn value_err(&self, field: &str, message: impl Into<String>) -> GrammarError {
        GrammarError::Value {
            file: self.file.to_string(),
            line: self.line,
            field: field.to_string(),
            message: message.into(),
        }
    }

    /// Parses a whole line segment as one constant expression.
    fn constant(
        &self,
        text: &str,
        col0: usize,
        consts: &HashMap<String, f64>,
        field: &str,
    ) -> Result<f64, GrammarError> {
        let scope = Consts(consts);
        let mut p = self.parser(text, col0, &scope);
        let e = p.expr()?;
        if p.peek().is_some() {
            return Err(p.error("end of line"));
        }
        match e {
            Expr::Num(v) if v.is_finite() => Ok(v),
            Expr::Num(v) => Err(self.value_err(field, format!("value {v} is not finite"))),
            _ => Err(self.value_err(field, "expected a constant")),
        }
    }

    /// Parses a list of numbers separated by whitespace.
    fn numbers(
        &self,
        text: &str,
        col0: usize,
        consts: &HashMap<String, f64>,
        field: &str,
        n: usize,
    ) -> Result<Vec<f64>, GrammarError> {
        let mut out = Vec::new();
        let mut offset = 0;
        for tok in text.split_whitespace() {
            let at = text[offset..].find(tok).map_or(offset, |i| i + offset);
            offset = at + tok.len();
            out.push(self.constant(tok, col0 + at, consts, field)?);
        }
        if out.len() != n {
            return Err(GrammarError::Syntax {
                file: self.file.to_string(),
                line: self.line,
                column: col0 + 1,
                expected: format!("{n} numbers for `{field}`"),
                found: format!("{}", out.len()),
            });
        }
        Ok(out)
    }
}

/// Parses a module string (axiom or successor) with the given scope.
fn modules<S: Scope>(p: &mut ExprParser<'_, S>) -> Result<Vec<(u8, Vec<Expr>)>, GrammarError> {
    let mut out = Vec::new();
    while let Some(c) = p.peek() {
        if !c.is_ascii_graphic() || c == b'(' || c == b')' || c == b',' {
            return Err(p.error("a module symbol (an ASCII character other than `(`, `)` or `,`)"));
        }
        let sym_pos = p.pos;
        p.pos += 1;
        let mut args = Vec::new();
        if p.src.get(p.pos) == Some(&b'(') {
            p.pos += 1;
            loop {
                let start = p.pos;
                let e = p.expr()?;
                if let Expr::Num(v) = e
                    && !v.is_finite()
                {
                    p.pos = start;
                    return Err(p.error(&format!("a finite parameter (this one evaluates to {v})")));
                }
                args.push(e);
                match p.peek() {
                    Some(b',') => p.pos += 1,
                    Some(b')') => {
                        p.pos += 1;
                        break;
                    }
                    _ => return Err(p.error("`,` or `)`")),
                }
            }
        }
        if let Some((lo, hi, what)) = turtle_arity(c) {
            if args.len() < lo || args.len() > hi {
                let end = p.pos;
                p.pos = sym_pos;
                let e = p.error(&format!("`{}` with {what}", c as char));
                p.pos = end;
                return Err(match e {
                    GrammarError::Syntax { file, line, column, expected, .. } => GrammarError::Syntax {
                        file,
                        line,
                        column,
                        expected,
                        found: format!("{} parameter(s)", args.len()),
                    },
                    e => e,
                });
            }
        }
        out.push((c, args));
    }
    Ok(out)
}

pub(super) fn parse(text: &str, file: &str, limits: &Limits) -> Result<Grammar, GrammarError> {
    let mut g = Grammar {
        name: std::path::Path::new(file)
            .file_stem()
            .map_or_else(|| file.to_string(), |s| s.to_string_lossy().into_owned()),
        file: file.to_string(),
        iterations: 5,
        angle: 90.0,
        step: 1.0,
        width: 1.0,
        scale: 1.0,
        width_scale: 0.01,
        tropism: None,
        leaf: (0.1, 0.05),
        wood: WoodProperties::default(),
        axiom: Vec::new(),
        productions: Vec::new(),
    };
    let mut consts: HashMap<String, f64> = HashMap::new();
    let mut axiom_seen = false;
    for (ln, raw) in text.lines().enumerate() {
        let ctx = Ctx { file, line: ln + 1, max_depth: limits.max_expression_depth };
        let line = strip_comment(raw);
        let trimmed = line.trim_start();
        if trimmed.trim().is_empty() {
            continue;
        }
        let indent = line.len() - trimmed.len();
        if let Some(arrow) = line.find("->") {
            g.productions.push(production(&ctx, line, arrow, &consts)?);
            continue;
        }
        if let Some(rest) = trimmed.strip_prefix("define") {
            if rest.starts_with([' ', '\t']) {
                let col = indent + 6;
                let Some(eq) = rest.find('=') else {
                    return Err(GrammarError::Syntax {
                        file: file.into(),
                        line: ln + 1,
                        column: col + rest.len() + 1,
                        expected: "`define NAME = value`".into(),
                        found: "end of line".into(),
                    });
                };
                let name = rest[..eq].trim();
                let valid = !name.is_empty()
                    && name.bytes().next().is_some_and(|c| c.is_ascii_alphabetic() || c == b'_')
                    && name.bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_');
                if !valid {
                    return Err(GrammarError::Syntax {
                        file: file.into(),
                        line: ln + 1,
                        column: col + 2,
                        expected: "a constant name (letters, digits, `_`)".into(),
                        found: format!("`{name}`"),
                    });
                }
                let v = ctx.constant(&rest[eq + 1..], col + eq + 1, &consts, name)?;
                consts.insert(name.to_string(), v);
                continue;
            }
        }
        let Some(colon) = trimmed.find(':') else {
            return Err(GrammarError::Syntax {
                file: file.into(),
                line: ln + 1,
                column: indent + 1,
                expected: "a setting (`axiom:`, `iterations:`, …), `define NAME = value`, or a production `A -> …`"
                    .into(),
                found: format!("`{}`", trimmed.trim_end()),
            });
        };
        let key = trimmed[..colon].trim();
        let value = &trimmed[colon + 1..];
        let vcol = indent + colon + 1;
        match key {
            "name" => g.name = value.trim().to_string(),
            "iterations" => {
                let v = ctx.constant(value, vcol, &consts, key)?;
                if v < 0.0 || v.fract() != 0.0 {
                    return Err(ctx.value_err(key, format!("expected a whole number ≥ 0, found {v}")));
                }
                if v > limits.max_iterations as f64 {
                    return Err(GrammarError::Limit {
                        file: file.into(),
                        line: ln + 1,
                        column: vcol + 1,
                        limit: "max_iterations",
                        value: limits.max_iterations as usize,
                    });
                }
                g.iterations = v as u32;
            }
            "angle" => g.angle = ctx.constant(value, vcol, &consts, key)?,
            "step" | "width" | "scale" | "width-scale" => {
                let v = ctx.constant(value, vcol, &consts, key)?;
                if v <= 0.0 {
                    return Err(ctx.value_err(key, format!("expected a value > 0, found {v}")));
                }
                match key {
                    "step" => g.step = v,
                    "width" => g.width = v,
                    "scale" => g.scale = v,
                    _ => g.width_scale = v,
                }
            }
            "tropism" => {
                let v = ctx.numbers(value, vcol, &consts, key, 4)?;
                let t = DVec3::new(v[0], v[1], v[2]);
                if t.length() == 0.0 {
                    return Err(ctx.value_err(key, "the tropism vector must not be zero"));
                }
                g.tropism = Some((t.normalize(), v[3]));
            }
            "leaf" => {
                let v = ctx.numbers(value, vcol, &consts, key, 2)?;
                if v[0] <= 0.0 || v[1] <= 0.0 {
                    return Err(ctx.value_err(key, "leaf length and width must be > 0"));
                }
                g.leaf = (v[0], v[1]);
            }
            "wood" => {
                let v = ctx.numbers(value, vcol, &consts, key, 2)?;
                if v[0] <= 0.0 || v[1] <= 0.0 {
                    return Err(ctx.value_err(key, "Young's modulus (Pa) and density (kg/m³) must be > 0"));
                }
                g.wood.young_modulus = v[0] as f32;
                g.wood.density = v[1] as f32;
            }
            "axiom" => {
                let scope = Consts(&consts);
                let mut p = ctx.parser(value, vcol, &scope);
                let ms = modules(&mut p)?;
                if ms.is_empty() {
                    return Err(p.error("at least one module in the axiom"));
                }
                g.axiom = ms
                    .into_iter()
                    .map(|(s, args)| {
                        let vals = args
                            .iter()
                            .map(|e| match e {
                                Expr::Num(v) => Ok(*v),
                                _ => Err(ctx.value_err("axiom", "axiom parameters must be constants")),
                            })
                            .collect::<Result<Vec<_>, _>>()?;
                        Ok((s, vals))
                    })
                    .collect::<Result<_, GrammarError>>()?;
                axiom_seen = true;
            }
            other => {
                return Err(GrammarError::Syntax {
                    file: file.into(),
                    line: ln + 1,
                    column: indent + 1,
                    expected: "one of the settings name, iterations, angle, step, width, scale, width-scale, tropism, leaf, wood, axiom".into(),
                    found: format!("`{other}`"),
                });
            }
        }
    }
    if !axiom_seen {
        return Err(GrammarError::Syntax {
            file: file.into(),
            line: text.lines().count().max(1),
            column: 1,
            expected: "an `axiom:` line".into(),
            found: "end of file".into(),
        });
    }
    Ok(g)
}

fn production(
    ctx: &Ctx<'_>,
    line: &str,
    arrow: usize,
    consts: &HashMap<String, f64>,
) -> Result<Production, GrammarError> {
    let left = &line[..arrow];
    let (pred_text, cond_text) = match left.find(':') {
        Some(c) => (&left[..c], Some((&left[c + 1..], c + 1))),
        None => (left, None),
    };
    // Predecessor: symbol and formal parameter names.
    let no_scope = Consts(consts);
    let mut p = ctx.parser(pred_text, 0, &no_scope);
    let Some(sym) = p.peek() else {
        return Err(p.error("a predecessor symbol before `->`"));
    };
    if !sym.is_ascii_graphic() || sym == b'(' || sym == b')' || sym == b',' {
        return Err(p.error("a predecessor symbol"));
    }
    p.pos += 1;
    let mut names: Vec<String> = Vec::new();
    if p.src.get(p.pos) == Some(&b'(') {
        p.pos += 1;
        loop {
            p.skip_ws();
            let start = p.pos;
            while p.pos < p.src.len() && (p.src[p.pos].is_ascii_alphanumeric() || p.src[p.pos] == b'_') {
                p.pos += 1;
            }
            if start == p.pos || p.src[start].is_ascii_digit() {
                p.pos = start;
                return Err(p.error("a formal parameter name"));
            }
            let name = std::str::from_utf8(&p.src[start..p.pos]).unwrap_or("").to_string();
            if names.contains(&name) {
                p.pos = start;
                return Err(p.error("a parameter name not used twice"));
            }
            names.push(name);
            match p.peek() {
                Some(b',') => p.pos += 1,
                Some(b')') => {
                    p.pos += 1;
                    break;
                }
                _ => return Err(p.error("`,` or `)`")),
            }
        }
    }
    if p.peek().is_some() {
        return Err(p.error(if cond_text.is_some() { "`:`" } else { "`:` or `->`" }));
    }
    if let Some((_, _, _)) = turtle_arity(sym) {
        let (lo, hi, what) = turtle_arity(sym).unwrap_or((0, 0, ""));
        if names.len() < lo || names.len() > hi {
            return Err(GrammarError::Syntax {
                file: ctx.file.into(),
                line: ctx.line,
                column: 1 + pred_text.len() - pred_text.trim_start().len(),
                expected: format!("`{}` with {what}", sym as char),
                found: format!("{} parameter(s)", names.len()),
            });
        }
    }
    let scope = Params { names: &names, consts };
    // Condition.
    let cond = match cond_text {
        None => None,
        Some((text, col)) if text.trim() == "*" => {
            let _ = col;
            None
        }
        Some((text, col)) => {
            let mut p = ctx.parser(text, col, &scope);
            let e = p.expr()?;
            if p.peek().is_some() {
                return Err(p.error("`->` after the condition"));
            }
            Some(e)
        }
    };
    // Probability and successor.
    let right = &line[arrow + 2..];
    let col = arrow + 2;
    let mut p = ctx.parser(right, col, &scope);
    let mut prob = None;
    if p.peek() == Some(b'(') {
        p.pos += 1;
        let e = p.expr()?;
        if p.peek() != Some(b')') {
            return Err(p.error("`)` after the probability"));
        }
        p.pos += 1;
        match e {
            Expr::Num(v) if v.is_finite() && v >= 0.0 => prob = Some(v),
            _ => return Err(ctx.value_err("probability", "expected a constant ≥ 0")),
        }
    }
    let succ = modules(&mut p)?;
    Ok(Production { pred: sym, arity: names.len(), cond, prob, succ, line: ctx.line })
}
