//! Expression syntax: tokens, the syntax tree and its recursive-descent parser.
//!
//! Grammar (lowest precedence first; `^` is right-associative and binds tighter than a
//! unary sign, so `-x^2 = -(x^2)` and `2^-x = 2^(-x)`):
//!
//! ```text
//! expr    := and ("or" and)*
//! and     := not ("and" not)*
//! not     := "not" not | compare
//! compare := sum (("<" | "<=" | ">" | ">=" | "==" | "!=") sum)?
//! sum     := product (("+" | "-") product)*
//! product := unary (("*" | "/") unary)*
//! unary   := ("-" | "+") unary | power
//! power   := atom ("^" unary)?
//! atom    := number | name | name "(" expr ("," expr)* ")" | "(" expr ")"
//! ```

/// Deepest nesting of parentheses, calls and unary operators accepted (the parser is
/// recursive; a bound keeps hostile input from exhausting the stack).
pub const MAX_DEPTH: usize = 200;

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `a + b`
    Add,
    /// `a - b`
    Sub,
    /// `a * b`
    Mul,
    /// `a / b`
    Div,
    /// `a ^ b`
    Pow,
    /// `a < b`
    Lt,
    /// `a <= b`
    Le,
    /// `a > b`
    Gt,
    /// `a >= b`
    Ge,
    /// `a == b`
    Eq,
    /// `a != b`
    Ne,
    /// `a and b`
    And,
    /// `a or b`
    Or,
}

/// A built-in function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Func {
    /// sin x
    Sin,
    /// cos x
    Cos,
    /// tan x
    Tan,
    /// eˣ
    Exp,
    /// natural logarithm
    Ln,
    /// √x
    Sqrt,
    /// |x|
    Abs,
    /// sign x ∈ {−1, 0, 1}
    Sign,
    /// tanh x
    Tanh,
    /// arctan x
    Atan,
    /// min(a, b)
    Min,
    /// max(a, b)
    Max,
    /// pow(a, b) = a^b
    Pow,
    /// if(condition, a, b)
    If,
}

impl Func {
    /// Every function, with its name in the language.
    pub const ALL: [(&'static str, Func); 14] = [
        ("sin", Func::Sin),
        ("cos", Func::Cos),
        ("tan", Func::Tan),
        ("exp", Func::Exp),
        ("ln", Func::Ln),
        ("sqrt", Func::Sqrt),
        ("abs", Func::Abs),
        ("sign", Func::Sign),
        ("tanh", Func::Tanh),
        ("atan", Func::Atan),
        ("min", Func::Min),
        ("max", Func::Max),
        ("pow", Func::Pow),
        ("if", Func::If),
    ];

    /// The function called `name`.
    pub fn by_name(name: &str) -> Option<Func> {
        Self::ALL.iter().find(|(n, _)| *n == name).map(|&(_, f)| f)
    }

    /// Its name in the language.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, f)| *f == self)
            .map_or("?", |(n, _)| n)
    }

    /// How many arguments it takes.
    pub fn arity(self) -> usize {
        match self {
            Func::Min | Func::Max | Func::Pow => 2,
            Func::If => 3,
            _ => 1,
        }
    }
}

/// Words that cannot name a state, input, parameter or `[let]` quantity: the time `t`,
/// the constant `pi`, the logical words and the function names.
pub fn is_reserved(name: &str) -> bool {
    matches!(name, "t" | "pi" | "and" | "or" | "not") || Func::by_name(name).is_some()
}

/// Whether `name` is an identifier: a letter or `_`, then letters, digits or `_`.
pub fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// A node of the syntax tree with the byte offset `pos` of its first character (for a
/// binary operation: of the operator) in the expression string.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// What the node is.
    pub kind: ExprKind,
    /// Byte offset in the expression string.
    pub pos: usize,
    /// Height of the tree below and including this node (a leaf has 1).
    depth: usize,
}

impl Expr {
    /// Height of the tree below and including this node (a leaf has 1); at most
    /// [`MAX_TREE_DEPTH`], so that recursive walks of the tree stay shallow.
    pub fn depth(&self) -> usize {
        self.depth
    }
}

/// Tallest syntax tree accepted (a chain `a + b + …` of n terms is n levels tall).
pub const MAX_TREE_DEPTH: usize = 1000;

/// A node over `children`, refused when taller than [`MAX_TREE_DEPTH`].
fn node(kind: ExprKind, pos: usize) -> Result<Expr, SyntaxError> {
    let children = match &kind {
        ExprKind::Num(_) | ExprKind::Name(_) => 0,
        ExprKind::Neg(a) | ExprKind::Not(a) => a.depth,
        ExprKind::Binary(_, a, b) => a.depth.max(b.depth),
        ExprKind::Call(_, args) => args.iter().map(|a| a.depth).max().unwrap_or(0),
    };
    let depth = children + 1;
    if depth > MAX_TREE_DEPTH {
        return Err(err(
            pos,
            format!("expression too long or nested too deeply (more than {MAX_TREE_DEPTH} levels); split it with [let]"),
        ));
    }
    Ok(Expr { kind, pos, depth })
}

/// The kinds of syntax-tree nodes.
#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// A number literal.
    Num(f64),
    /// A name (state, input, parameter, `[let]` quantity, `t` or `pi`).
    Name(String),
    /// `-a`
    Neg(Box<Expr>),
    /// `not a`
    Not(Box<Expr>),
    /// `a op b`
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `f(args)`
    Call(Func, Vec<Expr>),
}

/// A syntax error at byte `pos` of the expression string.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SyntaxError {
    /// Byte offset in the expression string.
    pub pos: usize,
    /// One-line message.
    pub message: String,
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Ident(String),
    Op(&'static str),
    LParen,
    RParen,
    Comma,
    End,
}

/// Parses one expression.
///
/// ```
/// use hysid_equations::ast::{parse, ExprKind, BinOp};
/// let e = parse("-x^2").unwrap();
/// assert!(matches!(e.kind, ExprKind::Neg(_)));
/// assert!(parse("(x").is_err());
/// ```
pub fn parse(text: &str) -> Result<Expr, SyntaxError> {
    let tokens = tokenize(text)?;
    let mut p = Parser {
        tokens,
        at: 0,
        depth: 0,
    };
    let e = p.expr()?;
    match p.peek() {
        Tok::End => Ok(e),
        Tok::RParen => Err(p.error("unbalanced parentheses: ')' without a matching '('")),
        other => Err(p.error(format!(
            "unexpected {} after a complete expression (missing operator?)",
            describe(other)
        ))),
    }
}

fn describe(t: &Tok) -> String {
    match t {
        Tok::Num(v) => format!("number {v}"),
        Tok::Ident(s) => format!("name '{s}'"),
        Tok::Op(o) => format!("'{o}'"),
        Tok::LParen => "'('".into(),
        Tok::RParen => "')'".into(),
        Tok::Comma => "','".into(),
        Tok::End => "end of expression".into(),
    }
}

fn tokenize(text: &str) -> Result<Vec<(Tok, usize)>, SyntaxError> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let start = i;
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if c.is_ascii_digit() || c == b'.' {
            i = number_end(bytes, i);
            let word = &text[start..i];
            out.push((Tok::Num(number(word, start)?), start));
            continue;
        }
        if c.is_ascii_alphabetic() || c == b'_' {
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            out.push((Tok::Ident(text[start..i].to_string()), start));
            continue;
        }
        let two = text.get(i..i + 2).unwrap_or("");
        let (tok, len) = match (c, two) {
            (_, "<=") => (Tok::Op("<="), 2),
            (_, ">=") => (Tok::Op(">="), 2),
            (_, "==") => (Tok::Op("=="), 2),
            (_, "!=") => (Tok::Op("!="), 2),
            (_, "**") => return Err(err(start, "'**' is not an operator: write powers as a^b")),
            (_, "&&") | (_, "||") => {
                return Err(err(start, "use the words 'and', 'or', 'not' for logic"))
            }
            (b'+', _) => (Tok::Op("+"), 1),
            (b'-', _) => (Tok::Op("-"), 1),
            (b'*', _) => (Tok::Op("*"), 1),
            (b'/', _) => (Tok::Op("/"), 1),
            (b'^', _) => (Tok::Op("^"), 1),
            (b'<', _) => (Tok::Op("<"), 1),
            (b'>', _) => (Tok::Op(">"), 1),
            (b'(', _) => (Tok::LParen, 1),
            (b')', _) => (Tok::RParen, 1),
            (b',', _) => (Tok::Comma, 1),
            (b'=', _) => return Err(err(start, "'=' is not an operator: compare with '=='")),
            _ => {
                let ch = text[start..].chars().next().unwrap_or('?');
                return Err(err(start, format!("unexpected character '{ch}'")));
            }
        };
        out.push((tok, start));
        i += len;
    }
    out.push((Tok::End, text.len()));
    Ok(out)
}

/// End of the number-like word starting at `i`: digits, letters, `_`, `.`, and a sign
/// right after an exponent `e`/`E` (so that `1e-3` is one word and `2x` a bad number).
fn number_end(bytes: &[u8], mut i: usize) -> usize {
    while i < bytes.len() {
        let c = bytes[i];
        let sign_after_e = (c == b'+' || c == b'-')
            && i > 0
            && matches!(bytes[i - 1], b'e' | b'E')
            && bytes[..i - 1]
                .last()
                .is_some_and(|d| d.is_ascii_digit() || *d == b'.');
        if c.is_ascii_alphanumeric() || c == b'_' || c == b'.' || sign_after_e {
            i += 1;
        } else {
            break;
        }
    }
    i
}

/// A decimal number `digits[.digits][(e|E)[+-]digits]` (either side of the point may be
/// empty, not both); finite.
fn number(word: &str, pos: usize) -> Result<f64, SyntaxError> {
    let bad = || {
        err(
            pos,
            format!("bad number '{word}' (write e.g. 2, 0.5, 1.5e-3)"),
        )
    };
    let (mantissa, exponent) = match word.find(['e', 'E']) {
        Some(k) => (&word[..k], Some(&word[k + 1..])),
        None => (word, None),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if !digits(int) || !digits(frac) || (int.is_empty() && frac.is_empty()) {
        return Err(bad());
    }
    if let Some(e) = exponent {
        let e = e.strip_prefix(['+', '-']).unwrap_or(e);
        if e.is_empty() || !digits(e) {
            return Err(bad());
        }
    }
    let v: f64 = word.parse().map_err(|_| bad())?;
    if !v.is_finite() {
        return Err(err(
            pos,
            format!("non-finite number '{word}' (outside the range of f64)"),
        ));
    }
    Ok(v)
}

fn err(pos: usize, message: impl Into<String>) -> SyntaxError {
    SyntaxError {
        pos,
        message: message.into(),
    }
}

struct Parser {
    tokens: Vec<(Tok, usize)>,
    at: usize,
    depth: usize,
}

impl Parser {
    fn peek(&self) -> &Tok {
        &self.tokens[self.at.min(self.tokens.len() - 1)].0
    }

    fn pos(&self) -> usize {
        self.tokens[self.at.min(self.tokens.len() - 1)].1
    }

    fn bump(&mut self) -> (Tok, usize) {
        let t = self.tokens[self.at.min(self.tokens.len() - 1)].clone();
        if self.at < self.tokens.len() - 1 {
            self.at += 1;
        }
        t
    }

    fn error(&self, message: impl Into<String>) -> SyntaxError {
        err(self.pos(), message)
    }

    fn is_word(&self, w: &str) -> bool {
        matches!(self.peek(), Tok::Ident(s) if s == w)
    }

    fn is_op(&self, o: &str) -> bool {
        matches!(self.peek(), Tok::Op(s) if *s == o)
    }

    /// Enters one level of nesting, refusing past [`MAX_DEPTH`].
    fn enter(&mut self) -> Result<(), SyntaxError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.error(format!(
                "expression nested too deeply (more than {MAX_DEPTH} levels); split it with [let]"
            )));
        }
        Ok(())
    }

    fn expr(&mut self) -> Result<Expr, SyntaxError> {
        self.enter()?;
        let mut left = self.and()?;
        while self.is_word("or") {
            let (_, pos) = self.bump();
            let right = self.and()?;
            left = binary(BinOp::Or, left, right, pos)?;
        }
        self.depth -= 1;
        Ok(left)
    }

    fn and(&mut self) -> Result<Expr, SyntaxError> {
        let mut left = self.not()?;
        while self.is_word("and") {
            let (_, pos) = self.bump();
            let right = self.not()?;
            left = binary(BinOp::And, left, right, pos)?;
        }
        Ok(left)
    }

    fn not(&mut self) -> Result<Expr, SyntaxError> {
        if self.is_word("not") {
            let (_, pos) = self.bump();
            self.enter()?;
            let inner = self.not()?;
            self.depth -= 1;
            return node(ExprKind::Not(Box::new(inner)), pos);
        }
        self.compare()
    }

    fn compare(&mut self) -> Result<Expr, SyntaxError> {
        let left = self.sum()?;
        let op = match self.peek() {
            Tok::Op("<") => BinOp::Lt,
            Tok::Op("<=") => BinOp::Le,
            Tok::Op(">") => BinOp::Gt,
            Tok::Op(">=") => BinOp::Ge,
            Tok::Op("==") => BinOp::Eq,
            Tok::Op("!=") => BinOp::Ne,
            _ => return Ok(left),
        };
        let (_, pos) = self.bump();
        let right = self.sum()?;
        if matches!(self.peek(), Tok::Op("<" | "<=" | ">" | ">=" | "==" | "!=")) {
            return Err(self.error("comparisons do not chain: write 'a < b and b < c'"));
        }
        binary(op, left, right, pos)
    }

    fn sum(&mut self) -> Result<Expr, SyntaxError> {
        let mut left = self.product()?;
        loop {
            let op = if self.is_op("+") {
                BinOp::Add
            } else if self.is_op("-") {
                BinOp::Sub
            } else {
                return Ok(left);
            };
            let (_, pos) = self.bump();
            let right = self.product()?;
            left = binary(op, left, right, pos)?;
        }
    }

    fn product(&mut self) -> Result<Expr, SyntaxError> {
        let mut left = self.unary()?;
        loop {
            let op = if self.is_op("*") {
                BinOp::Mul
            } else if self.is_op("/") {
                BinOp::Div
            } else {
                return Ok(left);
            };
            let (_, pos) = self.bump();
            let right = self.unary()?;
            left = binary(op, left, right, pos)?;
        }
    }

    fn unary(&mut self) -> Result<Expr, SyntaxError> {
        if self.is_op("-") || self.is_op("+") {
            let negate = self.is_op("-");
            let (_, pos) = self.bump();
            self.enter()?;
            let inner = self.unary()?;
            self.depth -= 1;
            return if negate {
                node(ExprKind::Neg(Box::new(inner)), pos)
            } else {
                Ok(inner)
            };
        }
        self.power()
    }

    fn power(&mut self) -> Result<Expr, SyntaxError> {
        let base = self.atom()?;
        if self.is_op("^") {
            let (_, pos) = self.bump();
            self.enter()?;
            let exponent = self.unary()?;
            self.depth -= 1;
            return binary(BinOp::Pow, base, exponent, pos);
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Expr, SyntaxError> {
        let (tok, pos) = self.bump();
        match tok {
            Tok::Num(v) => node(ExprKind::Num(v), pos),
            Tok::Ident(name) => {
                if matches!(self.peek(), Tok::LParen) {
                    return self.call(name, pos);
                }
                if matches!(name.as_str(), "and" | "or" | "not") {
                    return Err(err(pos, format!("'{name}' needs an operand before it")));
                }
                node(ExprKind::Name(name), pos)
            }
            Tok::LParen => {
                let inner = self.expr()?;
                if !matches!(self.peek(), Tok::RParen) {
                    return Err(match self.peek() {
                        Tok::End => err(pos, "unbalanced parentheses: this '(' is never closed"),
                        other => self.error(format!("expected ')' but found {}", describe(other))),
                    });
                }
                self.bump();
                Ok(inner)
            }
            Tok::RParen => Err(err(
                pos,
                "unbalanced parentheses: ')' without a matching '(' (or an empty '()')",
            )),
            Tok::End => Err(err(pos, "expression ends where a value is expected")),
            other => Err(err(
                pos,
                format!("expected a value but found {}", describe(&other)),
            )),
        }
    }

    fn call(&mut self, name: String, pos: usize) -> Result<Expr, SyntaxError> {
        let Some(func) = Func::by_name(&name) else {
            let known: Vec<&str> = Func::ALL.iter().map(|(n, _)| *n).collect();
            return Err(err(
                pos,
                format!(
                    "unknown function '{name}' (functions: {})",
                    known.join(", ")
                ),
            ));
        };
        let (_, open) = self.bump(); // '('
        self.enter()?;
        let mut args = Vec::new();
        if !matches!(self.peek(), Tok::RParen) {
            loop {
                args.push(self.expr()?);
                if matches!(self.peek(), Tok::Comma) {
                    self.bump();
                    continue;
                }
                break;
            }
        }
        match self.peek() {
            Tok::RParen => {
                self.bump();
            }
            Tok::End => {
                return Err(err(
                    open,
                    "unbalanced parentheses: this '(' is never closed",
                ))
            }
            other => {
                return Err(self.error(format!("expected ',' or ')' but found {}", describe(other))))
            }
        }
        self.depth -= 1;
        if args.len() != func.arity() {
            return Err(err(
                pos,
                format!(
                    "{name}() takes {} argument{}, not {}",
                    func.arity(),
                    if func.arity() == 1 { "" } else { "s" },
                    args.len()
                ),
            ));
        }
        node(ExprKind::Call(func, args), pos)
    }
}

fn binary(op: BinOp, left: Expr, right: Expr, pos: usize) -> Result<Expr, SyntaxError> {
    node(ExprKind::Binary(op, Box::new(left), Box::new(right)), pos)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape(e: &Expr) -> String {
        match &e.kind {
            ExprKind::Num(v) => format!("{v}"),
            ExprKind::Name(n) => n.clone(),
            ExprKind::Neg(a) => format!("(-{})", shape(a)),
            ExprKind::Not(a) => format!("(not {})", shape(a)),
            ExprKind::Binary(op, a, b) => format!("({} {op:?} {})", shape(a), shape(b)),
            ExprKind::Call(f, args) => format!(
                "{}({})",
                f.name(),
                args.iter().map(shape).collect::<Vec<_>>().join(",")
            ),
        }
    }

    fn p(s: &str) -> String {
        shape(&parse(s).unwrap())
    }

    #[test]
    fn precedence_and_associativity() {
        assert_eq!(p("a+b*c"), "(a Add (b Mul c))");
        assert_eq!(p("a-b-c"), "((a Sub b) Sub c)");
        assert_eq!(p("a/b/c"), "((a Div b) Div c)");
        assert_eq!(p("a^b^c"), "(a Pow (b Pow c))");
        assert_eq!(p("-x^2"), "(-(x Pow 2))");
        assert_eq!(p("2^-x"), "(2 Pow (-x))");
        assert_eq!(p("+x"), "x");
        assert_eq!(p("(a+b)*c"), "((a Add b) Mul c)");
        assert_eq!(
            p("a < b and not c >= d or e == f"),
            "(((a Lt b) And (not (c Ge d))) Or (e Eq f))"
        );
        assert_eq!(
            p("if(x != 0, min(a, b), pow(x, 2))"),
            "if((x Ne 0),min(a,b),pow(x,2))"
        );
    }

    #[test]
    fn numbers() {
        for (s, v) in [
            ("2", 2.0),
            ("0.5", 0.5),
            (".5", 0.5),
            ("5.", 5.0),
            ("1e3", 1e3),
            ("1.5E-3", 1.5e-3),
            ("2e+2", 200.0),
        ] {
            assert_eq!(parse(s).unwrap().kind, ExprKind::Num(v), "{s}");
        }
        for s in ["1.2.3", "2x", "1e", "1e+", ".", "1_0", "3.e"] {
            let e = parse(s).unwrap_err();
            assert!(e.message.starts_with("bad number"), "{s}: {}", e.message);
            assert_eq!(e.pos, 0);
        }
        let e = parse("x + 1e999").unwrap_err();
        assert_eq!(
            (e.pos, e.message.starts_with("non-finite number")),
            (4, true)
        );
    }

    #[test]
    fn errors_point_at_their_place() {
        let cases = [
            (
                "(x + 1",
                0,
                "unbalanced parentheses: this '(' is never closed",
            ),
            (
                "x + 1)",
                5,
                "unbalanced parentheses: ')' without a matching '('",
            ),
            (
                "sin(x",
                3,
                "unbalanced parentheses: this '(' is never closed",
            ),
            ("foo(x)", 0, "unknown function 'foo'"),
            ("max(x)", 0, "max() takes 2 arguments, not 1"),
            ("sin(x, y)", 0, "sin() takes 1 argument, not 2"),
            ("x $ y", 2, "unexpected character '$'"),
            ("x y", 2, "unexpected name 'y'"),
            ("a < b < c", 6, "comparisons do not chain"),
            ("x**2", 1, "'**' is not an operator"),
            ("x = 1", 2, "'=' is not an operator"),
            ("", 0, "expression ends where a value is expected"),
            ("x +", 3, "expression ends where a value is expected"),
        ];
        for (s, pos, msg) in cases {
            let e = parse(s).unwrap_err();
            assert_eq!(e.pos, pos, "{s}: {}", e.message);
            assert!(e.message.starts_with(msg), "{s}: {}", e.message);
        }
    }

    #[test]
    fn deep_nesting_is_refused_not_a_stack_overflow() {
        let deep = "(".repeat(100_000) + "x" + &")".repeat(100_000);
        assert!(parse(&deep)
            .unwrap_err()
            .message
            .contains("nested too deeply"));
        let minus = "-".repeat(100_000) + "x";
        assert!(parse(&minus).is_err());
        let ok = "(".repeat(50) + "x" + &")".repeat(50);
        assert_eq!(p(&ok), "x");
        let long = vec!["x"; 5000].join("+");
        assert!(parse(&long).unwrap_err().message.contains("too long"));
        let fine = vec!["x"; 500].join("+");
        assert_eq!(parse(&fine).unwrap().depth(), 500);
    }

    #[test]
    fn reserved_words_and_identifiers() {
        assert!(is_reserved("t") && is_reserved("sin") && is_reserved("if") && is_reserved("pi"));
        assert!(!is_reserved("x"));
        assert!(is_identifier("k_3") && is_identifier("_a") && !is_identifier("3k"));
        assert!(!is_identifier("a-b") && !is_identifier(""));
    }
}
