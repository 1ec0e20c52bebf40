//! Arithmetic and logical expressions in module parameters, conditions and probabilities.
//!
//! Grammar (lowest to highest precedence): `||`, `&&`, comparisons (`== != < <= > >=`),
//! `+ -`, `* / %`, unary `- !`, `^` (power, right-associative), then numbers, names
//! (formal parameters or `define`d constants; `pi`, `e`), calls
//! (`sin cos tan asin acos atan atan2 sqrt abs exp ln log floor ceil min max pow clamp`;
//! angles in degrees for the trigonometric functions, as turtle angles are) and parentheses.
//! Truth values are 1 and 0.

use super::GrammarError;

/// A compiled expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A constant.
    Num(f64),
    /// The n-th formal parameter of the predecessor.
    Param(u16),
    /// Negation.
    Neg(Box<Expr>),
    /// Logical not.
    Not(Box<Expr>),
    /// A binary operation.
    Bin(BinOp, Box<Expr>, Box<Expr>),
    /// A call of a built-in function.
    Call(Func, Vec<Expr>),
}

/// Binary operators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Pow,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    And,
    Or,
}

/// Built-in functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Sqrt,
    Abs,
    Exp,
    Ln,
    Log,
    Floor,
    Ceil,
    Min,
    Max,
    Pow,
    Clamp,
}

impl Func {
    fn lookup(name: &str) -> Option<(Func, usize)> {
        Some(match name {
            "sin" => (Func::Sin, 1),
            "cos" => (Func::Cos, 1),
            "tan" => (Func::Tan, 1),
            "asin" => (Func::Asin, 1),
            "acos" => (Func::Acos, 1),
            "atan" => (Func::Atan, 1),
            "atan2" => (Func::Atan2, 2),
            "sqrt" => (Func::Sqrt, 1),
            "abs" => (Func::Abs, 1),
            "exp" => (Func::Exp, 1),
            "ln" => (Func::Ln, 1),
            "log" => (Func::Log, 1),
            "floor" => (Func::Floor, 1),
            "ceil" => (Func::Ceil, 1),
            "min" => (Func::Min, 2),
            "max" => (Func::Max, 2),
            "pow" => (Func::Pow, 2),
            "clamp" => (Func::Clamp, 3),
            _ => return None,
        })
    }
}

#[inline]
fn truth(b: bool) -> f64 {
    if b { 1.0 } else { 0.0 }
}

impl Expr {
    /// Evaluates with the given actual parameters.
    pub fn eval(&self, p: &[f64]) -> f64 {
        match self {
            Expr::Num(v) => *v,
            Expr::Param(i) => p[*i as usize],
            Expr::Neg(a) => -a.eval(p),
            Expr::Not(a) => truth(a.eval(p) == 0.0),
            Expr::Bin(op, a, b) => {
                let x = a.eval(p);
                // Short-circuit logic.
                match op {
                    BinOp::And => return truth(x != 0.0 && b.eval(p) != 0.0),
                    BinOp::Or => return truth(x != 0.0 || b.eval(p) != 0.0),
                    _ => {}
                }
                let y = b.eval(p);
                match op {
                    BinOp::Add => x + y,
                    BinOp::Sub => x - y,
                    BinOp::Mul => x * y,
                    BinOp::Div => x / y,
                    BinOp::Rem => x % y,
                    BinOp::Pow => x.powf(y),
                    BinOp::Lt => truth(x < y),
                    BinOp::Le => truth(x <= y),
                    BinOp::Gt => truth(x > y),
                    BinOp::Ge => truth(x >= y),
                    BinOp::Eq => truth(x == y),
                    BinOp::Ne => truth(x != y),
                    BinOp::And | BinOp::Or => unreachable!(),
                }
            }
            Expr::Call(f, args) => {
                let a = |i: usize| args[i].eval(p);
                let d = std::f64::consts::PI / 180.0;
                match f {
                    Func::Sin => (a(0) * d).sin(),
                    Func::Cos => (a(0) * d).cos(),
                    Func::Tan => (a(0) * d).tan(),
                    Func::Asin => a(0).asin() / d,
                    Func::Acos => a(0).acos() / d,
                    Func::Atan => a(0).atan() / d,
                    Func::Atan2 => a(0).atan2(a(1)) / d,
                    Func::Sqrt => a(0).sqrt(),
                    Func::Abs => a(0).abs(),
                    Func::Exp => a(0).exp(),
                    Func::Ln => a(0).ln(),
                    Func::Log => a(0).log10(),
                    Func::Floor => a(0).floor(),
                    Func::Ceil => a(0).ceil(),
                    Func::Min => a(0).min(a(1)),
                    Func::Max => a(0).max(a(1)),
                    Func::Pow => a(0).powf(a(1)),
                    Func::Clamp => {
                        // Bounds in either order; NaN bounds give NaN (f64::clamp panics on them),
                        // which the turtle then refuses where the value is used.
                        let (lo, hi) = (a(1).min(a(2)), a(2).max(a(1)));
                        if lo.is_nan() || hi.is_nan() { f64::NAN } else { a(0).clamp(lo, hi) }
                    }
                }
            }
        }
    }

    /// Folds constant sub-expressions.
    fn fold(self) -> Expr {
        let constant = |e: &Expr| matches!(e, Expr::Num(_));
        let e = self;
        let all_const = match &e {
            Expr::Num(_) | Expr::Param(_) => return e,
            Expr::Neg(a) | Expr::Not(a) => constant(a),
            Expr::Bin(_, a, b) => constant(a) && constant(b),
            Expr::Call(_, args) => args.iter().all(constant),
        };
        if all_const { Expr::Num(e.eval(&[])) } else { e }
    }
}

/// Resolves a name to a formal parameter index or a constant value.
pub trait Scope {
    /// The value of a constant, or the index of a formal parameter.
    fn resolve(&self, name: &str) -> Option<Result<f64, u16>>;
}

/// Recursive-descent parser over one line of text.
pub struct ExprParser<'a, S: Scope> {
    pub(super) src: &'a [u8],
    pub(super) pos: usize,
    pub(super) file: &'a str,
    pub(super) line: usize,
    pub(super) col0: usize,
    pub(super) scope: &'a S,
    pub(super) depth: usize,
    pub(super) max_depth: usize,
}

impl<'a, S: Scope> ExprParser<'a, S> {
    pub(super) fn error(&self, expected: &str) -> GrammarError {
        let found = self.found();
        GrammarError::Syntax {
            file: self.file.to_string(),
            line: self.line,
            column: self.col0 + self.pos + 1,
            expected: expected.to_string(),
            found,
        }
    }

    pub(super) fn found(&self) -> String {
        match std::str::from_utf8(&self.src[self.pos.min(self.src.len())..]) {
            Ok(rest) => match rest.chars().next() {
                None => "end of line".to_string(),
                Some(c) => format!("`{c}`"),
            },
            Err(_) => "a non-UTF-8 byte".to_string(),
        }
    }

    pub(super) fn skip_ws(&mut self) {
        while self.pos < self.src.len() && (self.src[self.pos] == b' ' || self.src[self.pos] == b'\t') {
            self.pos += 1;
        }
    }

    pub(super) fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.src.get(self.pos).copied()
    }

    fn eat(&mut self, s: &str) -> bool {
        self.skip_ws();
        if self.src[self.pos..].starts_with(s.as_bytes()) {
            self.pos += s.len();
            true
        } else {
            false
        }
    }

    /// Parses a full expression.
    pub fn expr(&mut self) -> Result<Expr, GrammarError> {
        self.depth += 1;
        if self.depth > self.max_depth {
            return Err(GrammarError::Limit {
                file: self.file.to_string(),
                line: self.line,
                column: self.col0 + self.pos + 1,
                limit: "max_expression_depth",
                value: self.max_depth,
            });
        }
        let e = self.or();
        self.depth -= 1;
        Ok(e?.fold())
    }

    fn or(&mut self) -> Result<Expr, GrammarError> {
        let mut a = self.and()?;
        while self.eat("||") {
            let b = self.and()?;
            a = Expr::Bin(BinOp::Or, Box::new(a), Box::new(b)).fold();
        }
        Ok(a)
    }

    fn and(&mut self) -> Result<Expr, GrammarError> {
        let mut a = self.cmp()?;
        while self.eat("&&") {
            let b = self.cmp()?;
            a = Expr::Bin(BinOp::And, Box::new(a), Box::new(b)).fold();
        }
        Ok(a)
    }

    fn cmp(&mut self) -> Result<Expr, GrammarError> {
        let a = self.sum()?;
        for (tok, op) in [
            ("==", BinOp::Eq),
            ("!=", BinOp::Ne),
            ("<=", BinOp::Le),
            (">=", BinOp::Ge),
            ("<", BinOp::Lt),
            (">", BinOp::Gt),
        ] {
            if self.eat(tok) {
                let b = self.sum()?;
                return Ok(Expr::Bin(op, Box::new(a), Box::new(b)).fold());
            }
        }
        Ok(a)
    }

    fn sum(&mut self) -> Result<Expr, GrammarError> {
        let mut a = self.product()?;
        loop {
            let op = match self.peek() {
                Some(b'+') => BinOp::Add,
                Some(b'-') => BinOp::Sub,
                _ => return Ok(a),
            };
            self.pos += 1;
            let b = self.product()?;
            a = Expr::Bin(op, Box::new(a), Box::new(b)).fold();
        }
    }

    fn product(&mut self) -> Result<Expr, GrammarError> {
        let mut a = self.unary()?;
        loop {
            let op = match self.peek() {
                Some(b'*') => BinOp::Mul,
                Some(b'/') => BinOp::Div,
                Some(b'%') => BinOp::Rem,
                _ => return Ok(a),
            };
            self.pos += 1;
            let b = self.unary()?;
            a = Expr::Bin(op, Box::new(a), Box::new(b)).fold();
        }
    }

    fn unary(&mut self) -> Result<Expr, GrammarError> {
        match self.peek() {
            Some(b'-') => {
                self.pos += 1;
                let a = self.nested(Self::unary)?;
                Ok(Expr::Neg(Box::new(a)).fold())
            }
            Some(b'!') if self.src.get(self.pos + 1) != Some(&b'=') => {
                self.pos += 1;
                let a = self.nested(Self::unary)?;
                Ok(Expr::Not(Box::new(a)).fold())
            }
            _ => self.power(),
        }
    }

    fn nested(&mut self, f: fn(&mut Self) -> Result<Expr, GrammarError>) -> Result<Expr, GrammarError> {
        self.depth += 1;
        if self.depth > self.max_depth {
            return Err(GrammarError::Limit {
                file: self.file.to_string(),
                line: self.line,
                column: self.col0 + self.pos + 1,
                limit: "max_expression_depth",
                value: self.max_depth,
            });
        }
        let r = f(self);
        self.depth -= 1;
        r
    }

    fn power(&mut self) -> Result<Expr, GrammarError> {
        let base = self.primary()?;
        if self.peek() == Some(b'^') {
            self.pos += 1;
            let exp = self.nested(Self::unary)?;
            return Ok(Expr::Bin(BinOp::Pow, Box::new(base), Box::new(exp)).fold());
        }
        Ok(base)
    }

    fn primary(&mut self) -> Result<Expr, GrammarError> {
        match self.peek() {
            Some(b'(') => {
                self.pos += 1;
                let e = self.expr()?;
                if self.peek() != Some(b')') {
                    return Err(self.error("`)`"));
                }
                self.pos += 1;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => self.number(),
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let start = self.pos;
                while self.pos < self.src.len()
                    && (self.src[self.pos].is_ascii_alphanumeric() || self.src[self.pos] == b'_')
                {
                    self.pos += 1;
                }
                let name = std::str::from_utf8(&self.src[start..self.pos]).unwrap_or("");
                if self.peek() == Some(b'(') {
                    let Some((func, arity)) = Func::lookup(name) else {
                        self.pos = start;
                        return Err(self.error("a known function (sin, cos, sqrt, min, max, …)"));
                    };
                    self.pos += 1;
                    let mut args = Vec::new();
                    if self.peek() != Some(b')') {
                        loop {
                            args.push(self.expr()?);
                            if self.peek() == Some(b',') {
                                self.pos += 1;
                                continue;
                            }
                            break;
                        }
                    }
                    if self.peek() != Some(b')') {
                        return Err(self.error("`,` or `)`"));
                    }
                    if args.len() != arity {
                        return Err(self.error(&format!("`{name}` to take {arity} argument(s), not {}", args.len())));
                    }
                    self.pos += 1;
                    return Ok(Expr::Call(func, args).fold());
                }
                match name {
                    "pi" => return Ok(Expr::Num(std::f64::consts::PI)),
                    "e" if self.scope.resolve("e").is_none() => return Ok(Expr::Num(std::f64::consts::E)),
                    _ => {}
                }
                match self.scope.resolve(name) {
                    Some(Ok(v)) => Ok(Expr::Num(v)),
                    Some(Err(i)) => Ok(Expr::Param(i)),
                    None => {
                        self.pos = start;
                        Err(self.error(&format!("a parameter or defined constant (`{name}` is not defined)")))
                    }
                }
            }
            _ => Err(self.error("a number, name or `(`")),
        }
    }

    fn number(&mut self) -> Result<Expr, GrammarError> {
        let start = self.pos;
        while self.pos < self.src.len() && (self.src[self.pos].is_ascii_digit() || self.src[self.pos] == b'.') {
            self.pos += 1;
        }
        if self.pos < self.src.len() && (self.src[self.pos] == b'e' || self.src[self.pos] == b'E') {
            let save = self.pos;
            self.pos += 1;
            if self.pos < self.src.len() && (self.src[self.pos] == b'+' || self.src[self.pos] == b'-') {
                self.pos += 1;
            }
            if self.pos < self.src.len() && self.src[self.pos].is_ascii_digit() {
                while self.pos < self.src.len() && self.src[self.pos].is_ascii_digit() {
                    self.pos += 1;
                }
            } else {
                self.pos = save;
            }
        }
        let text = std::str::from_utf8(&self.src[start..self.pos]).unwrap_or("");
        text.parse::<f64>().map(Expr::Num).map_err(|_| {
            self.pos = start;
            self.error("a number")
        })
    }
}
