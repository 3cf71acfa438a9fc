//! An index expression with its names resolved once (issue 33).
//!
//! A family's `where` and the subscripts of its references (`P[i+1]`) are evaluated for every
//! member: 10^4 times for a chain. [`IndexExpr::eval`] looks each name up by text through a
//! closure (the member's indices, then the sizes, then the tables' columns) and carries a
//! located error through every node; that was ~650 instructions per `where`. A
//! [`IndexProgram`] is the same expression with each name replaced once by what it is — the
//! member's `k`-th index, or a size's value, which does not change while a file is read — and
//! flattened into postfix order. It computes exactly what [`IndexExpr::eval`] computes with
//! the same operations; it only has no messages: wherever the expression fails (a condition
//! where a number belongs, division by zero, overflow) it answers `None`, and the caller
//! evaluates the [`IndexExpr`] itself, which reports the error as before. An expression that
//! names a table's column or an unknown name is not compiled at all (`None` from
//! [`IndexProgram::compile`]): the caller keeps the general path.

use super::index_expr::{IndexExpr, IndexValue, Op};

/// What a name in an index expression is, for [`IndexProgram::compile`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Operand {
    /// The `k`-th of the values the program is evaluated with (a member's `k`-th index).
    Index(usize),
    /// A number that does not change (a size of `[indices]`).
    Constant(i64),
}

/// One step of the postfix program.
#[derive(Clone, Copy, Debug)]
enum Step {
    Push(Operand),
    Neg,
    Not,
    Binary(Op),
}

/// An index expression, its names resolved, in postfix order.
#[derive(Clone, Debug)]
pub(crate) struct IndexProgram {
    steps: Vec<Step>,
    /// The deepest the stack goes.
    depth: usize,
}

impl IndexProgram {
    /// `e` with each name resolved by `resolve`; `None` when a name resolves to nothing this
    /// program can hold (the general path then evaluates `e`).
    pub fn compile(e: &IndexExpr, resolve: &dyn Fn(&str) -> Option<Operand>) -> Option<Self> {
        let mut steps = Vec::new();
        push_steps(e, resolve, &mut steps)?;
        let mut depth = 0usize;
        let mut max = 0usize;
        for s in &steps {
            match s {
                Step::Push(_) => depth += 1,
                Step::Neg | Step::Not => {}
                Step::Binary(_) => depth -= 1,
            }
            max = max.max(depth);
        }
        Some(IndexProgram { steps, depth: max })
    }

    /// The value with `values` as the indices; `None` wherever [`IndexExpr::eval`] would fail.
    pub fn eval(&self, values: &[i64]) -> Option<IndexValue> {
        // Index expressions are short (`i >= 1 and i <= n` is 7 steps, 3 deep): on the stack,
        // a small one (zeroing 16 slots was a third of evaluating a `where`).
        let mut inline = [IndexValue::Int(0); 4];
        let mut spilled;
        let stack: &mut [IndexValue] = if self.depth <= inline.len() {
            &mut inline
        } else {
            spilled = vec![IndexValue::Int(0); self.depth];
            &mut spilled
        };
        // `compile` made the steps from a whole expression and measured `depth` from them:
        // every operator finds its operands on the stack, and no push goes past `depth`.
        let mut top = 0usize;
        for step in &self.steps {
            match *step {
                Step::Push(Operand::Index(k)) => {
                    stack[top] = IndexValue::Int(*values.get(k)?);
                    top += 1;
                }
                Step::Push(Operand::Constant(v)) => {
                    stack[top] = IndexValue::Int(v);
                    top += 1;
                }
                Step::Neg => {
                    stack[top - 1] = match stack[top - 1] {
                        IndexValue::Int(v) => IndexValue::Int(v.checked_neg()?),
                        IndexValue::Bool(_) => return None,
                    }
                }
                Step::Not => {
                    stack[top - 1] = match stack[top - 1] {
                        IndexValue::Bool(b) => IndexValue::Bool(!b),
                        IndexValue::Int(_) => return None,
                    }
                }
                Step::Binary(op) => {
                    top -= 1;
                    stack[top - 1] = binary(op, stack[top - 1], stack[top])?;
                }
            }
        }
        (top == 1).then_some(stack[0])
    }

    /// The value as an integer ([`IndexExpr::int`]).
    pub fn int(&self, values: &[i64]) -> Option<i64> {
        match self.eval(values)? {
            IndexValue::Int(v) => Some(v),
            IndexValue::Bool(_) => None,
        }
    }

    /// The value as a condition ([`IndexExpr::condition`]).
    pub fn condition(&self, values: &[i64]) -> Option<bool> {
        match self.eval(values)? {
            IndexValue::Bool(b) => Some(b),
            IndexValue::Int(_) => None,
        }
    }
}

fn push_steps(
    e: &IndexExpr,
    resolve: &dyn Fn(&str) -> Option<Operand>,
    steps: &mut Vec<Step>,
) -> Option<()> {
    match e {
        IndexExpr::Int(v) => steps.push(Step::Push(Operand::Constant(*v))),
        IndexExpr::Name(n, _) => steps.push(Step::Push(resolve(n)?)),
        IndexExpr::Neg(a) => {
            push_steps(a, resolve, steps)?;
            steps.push(Step::Neg);
        }
        IndexExpr::Not(a) => {
            push_steps(a, resolve, steps)?;
            steps.push(Step::Not);
        }
        // Both sides evaluated, as `IndexExpr::eval` does (no short circuit: a type error on
        // the right of `or` is an error there too).
        IndexExpr::Binary(op, a, b, _) => {
            push_steps(a, resolve, steps)?;
            push_steps(b, resolve, steps)?;
            steps.push(Step::Binary(*op));
        }
    }
    Some(())
}

/// [`IndexExpr::eval`]'s operators, `None` where it reports an error.
fn binary(op: Op, x: IndexValue, y: IndexValue) -> Option<IndexValue> {
    use IndexValue::{Bool, Int};
    match (op, x, y) {
        (Op::Or, Bool(a), Bool(b)) => Some(Bool(a || b)),
        (Op::And, Bool(a), Bool(b)) => Some(Bool(a && b)),
        (Op::Or | Op::And, _, _) => None,
        (_, Int(a), Int(b)) => match op {
            Op::Eq => Some(Bool(a == b)),
            Op::Ne => Some(Bool(a != b)),
            Op::Lt => Some(Bool(a < b)),
            Op::Le => Some(Bool(a <= b)),
            Op::Gt => Some(Bool(a > b)),
            Op::Ge => Some(Bool(a >= b)),
            Op::Add => a.checked_add(b).map(Int),
            Op::Sub => a.checked_sub(b).map(Int),
            Op::Mul => a.checked_mul(b).map(Int),
            Op::Div | Op::Rem if b == 0 => None,
            Op::Div => a.checked_div_euclid(b).map(Int),
            Op::Rem => a.checked_rem_euclid(b).map(Int),
            Op::Or | Op::And => None,
        },
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::index_expr::parse;

    /// Every expression gives what the general evaluation gives, or `None` where that fails.
    #[test]
    fn programs_compute_what_the_expressions_compute() {
        let texts = [
            "i >= 1 and i <= n",
            "i == 0 or i == n+1",
            "not (j == 0 and (i == 0 or i == n-1))",
            "i+1",
            "-i*2 - j % 3",
            "(i-1) % n",
            "i / (j - 2)",
            "i / 0",
            "i and j",
            "not i",
            "-(i < j)",
            "i + (j == 1)",
            "9223372036854775807 + i",
            "-(-9223372036854775807 - 1 + i)",
        ];
        let names = ["i", "j"];
        let resolve = |n: &str| match n {
            "n" => Some(Operand::Constant(5)),
            other => names.iter().position(|m| *m == other).map(Operand::Index),
        };
        let mut compared = 0;
        for text in texts {
            let e = parse(text).unwrap();
            let p = IndexProgram::compile(&e, &resolve).unwrap();
            for i in -3..8i64 {
                for j in -3..8i64 {
                    let lookup = |n: &str| -> Result<Option<i64>, String> {
                        Ok(match n {
                            "i" => Some(i),
                            "j" => Some(j),
                            "n" => Some(5),
                            _ => None,
                        })
                    };
                    assert_eq!(
                        p.eval(&[i, j]),
                        e.eval(&lookup).ok(),
                        "{text} at i={i}, j={j}"
                    );
                    compared += 1;
                }
            }
        }
        assert_eq!(compared, texts.len() * 121);
    }

    /// A name the resolver does not know (a table's column, an unknown name) is not compiled.
    #[test]
    fn unknown_names_are_left_to_the_general_path() {
        let e = parse("i + bars_a").unwrap();
        let resolve = |n: &str| (n == "i").then_some(Operand::Index(0));
        assert!(IndexProgram::compile(&e, &resolve).is_none());
    }

    /// Hand-computed values: 7 with i = 3 is `3 + 1`; `(0 - 1) % 5` wraps to 4; `-7 / 2` floors.
    #[test]
    fn values_by_hand() {
        let resolve = |n: &str| match n {
            "n" => Some(Operand::Constant(5)),
            "i" => Some(Operand::Index(0)),
            _ => None,
        };
        let prog = |t: &str| IndexProgram::compile(&parse(t).unwrap(), &resolve).unwrap();
        assert_eq!(prog("i+1").int(&[3]), Some(4));
        assert_eq!(prog("(i-1) % n").int(&[0]), Some(4));
        assert_eq!(prog("i / 2").int(&[-7]), Some(-4));
        assert_eq!(prog("i >= 1 and i <= n").condition(&[5]), Some(true));
        assert_eq!(prog("i >= 1 and i <= n").condition(&[6]), Some(false));
        assert_eq!(prog("i >= 1 and i <= n").int(&[6]), None);
    }
}
