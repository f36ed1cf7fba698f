//! The compiler: the instruction set of a formula ([`Op`], the functions it may call), one
//! formula compiled to a [`Program`] (the length limit, then the parser, whose errors get a
//! caret here), and the four programs of a surface merged into one [`Shared`] list of
//! nodes that computes each common value once. Apart from the parser, which walks the
//! grammar and emits these instructions, and from the evaluator, which runs them.

use super::messages::caret;
use super::parser::Parser;
use crate::limits::FORMULA_LENGTH;
use std::collections::BTreeMap;

/// The functions a formula may call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Fun {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Sinh,
    Cosh,
    Tanh,
    Exp,
    Log,
    Sqrt,
    Abs,
    Min,
    Max,
}

/// Each function's name in a formula.
pub(super) const FUNCTIONS: [(&str, Fun); 16] = [
    ("sin", Fun::Sin),
    ("cos", Fun::Cos),
    ("tan", Fun::Tan),
    ("asin", Fun::Asin),
    ("acos", Fun::Acos),
    ("atan", Fun::Atan),
    ("atan2", Fun::Atan2),
    ("sinh", Fun::Sinh),
    ("cosh", Fun::Cosh),
    ("tanh", Fun::Tanh),
    ("exp", Fun::Exp),
    ("log", Fun::Log),
    ("sqrt", Fun::Sqrt),
    ("abs", Fun::Abs),
    ("min", Fun::Min),
    ("max", Fun::Max),
];

/// The function called `name`, if there is one.
pub(super) fn function(name: &str) -> Option<Fun> {
    FUNCTIONS.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
}

impl Fun {
    /// How many arguments it takes.
    pub(super) fn arity(self) -> usize {
        match self {
            Fun::Atan2 | Fun::Min | Fun::Max => 2,
            _ => 1,
        }
    }

    /// Its name in a formula.
    pub(super) fn name(self) -> &'static str {
        FUNCTIONS
            .iter()
            .find(|(_, f)| *f == self)
            .map_or("?", |(n, _)| n)
    }
}

/// One instruction of a compiled formula, run on a stack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Op {
    Const(f64),
    U,
    V,
    Neg,
    Add,
    Sub,
    Mul,
    Div,
    /// The base to a constant integer power.
    PowI(i32),
    /// The base to a constant real power.
    PowF(f64),
    /// x^y for a varying exponent: exp(y ln x).
    Pow,
    Call(Fun),
}

impl Op {
    /// How many operands it takes from the stack.
    pub(super) fn arity(self) -> usize {
        match self {
            Op::Const(_) | Op::U | Op::V => 0,
            Op::Neg | Op::PowI(_) | Op::PowF(_) => 1,
            Op::Add | Op::Sub | Op::Mul | Op::Div | Op::Pow => 2,
            Op::Call(f) => f.arity(),
        }
    }
}

/// A compiled formula: a postfix program with every name resolved (u and v to their
/// instructions, parameters and constants to numbers, constant parts folded), so that a
/// run does no string work and no recursion.
#[derive(Clone, Debug)]
pub(super) struct Program {
    pub(super) ops: Vec<Op>,
    /// The characters `[start, end)` of the source each instruction computes.
    pub(super) spans: Vec<(usize, usize)>,
    /// The source's characters, for messages.
    pub(super) text: Vec<char>,
    /// The deepest the stack gets.
    pub(super) depth: usize,
}

impl Program {
    /// Compiles `text`; the error is the message a [`FieldError`] carries: what is wrong,
    /// and the formula with a caret under where.
    ///
    /// [`FieldError`]: crate::limits::FieldError
    pub(super) fn compile(
        text: &str,
        parameters: &BTreeMap<String, f64>,
    ) -> Result<Program, String> {
        if text.len() > FORMULA_LENGTH {
            return Err(format!(
                "the formula is {} bytes long, more than the {FORMULA_LENGTH} a formula may have",
                text.len()
            ));
        }
        let chars: Vec<char> = text.chars().collect();
        Parser::run(&chars, parameters).map_err(|e| {
            format!(
                "cannot read the formula at character {}: {}\n{}",
                e.at + 1,
                e.message,
                caret(&chars, e.at)
            )
        })
    }
}

/// The four programs as one list of nodes, each computed once for all four coordinates
/// (`cos(u)` in x and in y is one node: the built-in surfaces share such values by hand),
/// in an order where every node reads earlier ones. An operation with a constant operand
/// becomes one on the other operand alone (`r*cos(v)` scales, as the built-in surfaces
/// write it), which over [`Jet`]s skips the derivatives of the constant.
///
/// [`Jet`]: crate::surfaces::Jet
#[derive(Clone, Debug)]
pub(super) struct Shared {
    /// Each node and the nodes it reads (as many as it takes).
    pub(super) nodes: Vec<(Node, [u32; 2])>,
    /// The nodes of x, y, z and w.
    pub(super) outputs: [u32; 4],
}

/// A node of [`Shared`].
#[derive(Clone, Copy, Debug)]
pub(super) enum Node {
    /// An instruction of the programs.
    Op(Op),
    /// The operand times a constant.
    Scale(f64),
    /// The operand plus a constant.
    Shift(f64),
    /// The operand divided by a constant.
    Over(f64),
}

impl Node {
    /// How many nodes it reads.
    fn arity(self) -> usize {
        match self {
            Node::Op(op) => op.arity(),
            Node::Scale(_) | Node::Shift(_) | Node::Over(_) => 1,
        }
    }
}

impl Shared {
    /// The four programs merged, common values shared and constants folded into nodes.
    pub(super) fn new(programs: &[Program; 4]) -> Shared {
        use std::collections::HashMap;
        let key = |node: Node| -> (u8, u64) {
            match node {
                Node::Op(Op::Const(x)) => (0, x.to_bits()),
                Node::Op(Op::U) => (1, 0),
                Node::Op(Op::V) => (2, 0),
                Node::Op(Op::Neg) => (3, 0),
                Node::Op(Op::Add) => (4, 0),
                Node::Op(Op::Sub) => (5, 0),
                Node::Op(Op::Mul) => (6, 0),
                Node::Op(Op::Div) => (7, 0),
                Node::Op(Op::PowI(n)) => (8, u64::from(n as u32)),
                Node::Op(Op::PowF(k)) => (9, k.to_bits()),
                Node::Op(Op::Pow) => (10, 0),
                Node::Op(Op::Call(f)) => (11, f as u64),
                Node::Scale(k) => (12, k.to_bits()),
                Node::Shift(k) => (13, k.to_bits()),
                Node::Over(k) => (14, k.to_bits()),
            }
        };
        // Nodes 0 and 1 are u and v: a run starts with them in its registers.
        let mut nodes: Vec<(Node, [u32; 2])> =
            vec![(Node::Op(Op::U), [0, 0]), (Node::Op(Op::V), [0, 0])];
        let mut seen: HashMap<((u8, u64), [u32; 2]), u32> = HashMap::from([
            ((key(nodes[0].0), [0, 0]), 0),
            ((key(nodes[1].0), [0, 0]), 1),
        ]);
        let mut outputs = [0; 4];
        for (k, program) in programs.iter().enumerate() {
            let mut stack: Vec<u32> = Vec::with_capacity(program.depth);
            for op in &program.ops {
                let mut args = [0; 2];
                for i in (0..op.arity()).rev() {
                    args[i] = stack.pop().unwrap_or_default();
                }
                let constant = |id: u32| match nodes.get(id as usize) {
                    Some((Node::Op(Op::Const(c)), _)) => Some(*c),
                    _ => None,
                };
                let (a, b) = (constant(args[0]), constant(args[1]));
                let node = match (op, a, b) {
                    (Op::Mul, Some(c), None) => (Node::Scale(c), [args[1], 0]),
                    (Op::Mul, None, Some(c)) => (Node::Scale(c), [args[0], 0]),
                    (Op::Add, Some(c), None) => (Node::Shift(c), [args[1], 0]),
                    (Op::Add, None, Some(c)) => (Node::Shift(c), [args[0], 0]),
                    // a - c is a + (-c), exactly.
                    (Op::Sub, None, Some(c)) => (Node::Shift(-c), [args[0], 0]),
                    (Op::Div, None, Some(c)) => (Node::Over(c), [args[0], 0]),
                    _ => (Node::Op(*op), args),
                };
                let id = *seen.entry((key(node.0), node.1)).or_insert_with(|| {
                    nodes.push(node);
                    (nodes.len() - 1) as u32
                });
                stack.push(id);
            }
            outputs[k] = stack.pop().unwrap_or_default();
        }
        // Constants folded into scale, shift and division nodes are read by no node: drop
        // what the outputs do not need, renumbering the rest.
        let mut live = vec![false; nodes.len()];
        live[..2].fill(true);
        for o in outputs {
            live[o as usize] = true;
        }
        for i in (0..nodes.len()).rev() {
            if live[i] {
                let (node, args) = nodes[i];
                for &a in &args[..node.arity()] {
                    live[a as usize] = true;
                }
            }
        }
        let mut renumber = vec![0u32; nodes.len()];
        let mut kept = Vec::with_capacity(nodes.len());
        for (i, (node, args)) in nodes.into_iter().enumerate() {
            if live[i] {
                renumber[i] = kept.len() as u32;
                kept.push((node, args.map(|a| renumber[a as usize])));
            }
        }
        Shared {
            nodes: kept,
            outputs: outputs.map(|o| renumber[o as usize]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{compile_error, value};

    #[test]
    fn limits_hold_against_hostile_input() {
        let deep = "(".repeat(4000);
        assert!(compile_error(&deep, &[]).contains("deeper than 256 levels"));
        let e = compile_error(&"(".repeat(10_000), &[]);
        assert!(e.contains("10000 bytes long"), "{e}");
        let deep = format!("{}u{}", "(".repeat(300), ")".repeat(300));
        assert!(compile_error(&deep, &[]).contains("deeper than 256 levels"));
        let signs = format!("{}u", "-".repeat(300));
        assert!(compile_error(&signs, &[]).contains("deeper than 256 levels"));
        let powers = format!("{}u", "u^".repeat(300));
        assert!(compile_error(&powers, &[]).contains("deeper than 256 levels"));
        // At the limit, it parses and evaluates without recursion.
        let ok = format!("{}u{}", "(".repeat(200), ")".repeat(200));
        assert_eq!(value(&ok, 2.0, 0.0, &[]), 2.0);
        let long = "u+".repeat(2047) + "u";
        assert_eq!(value(&long, 1.0, 0.0, &[]), 2048.0);
        let e = compile_error(&"u+".repeat(3000), &[]);
        assert!(e.contains("6000 bytes long, more than the 4096"), "{e}");
    }
}
