//! A family's field read for each member from one template (issue 33).
//!
//! The members of a family read one text at one place in the file (`position = "[x[i], 0,
//! 0]"` for each of 10^4 particles). Lowering it symbolically for each member, with its index
//! put in, was half of reading a chain's particles. A text of the common shape — a vector (or
//! a scalar) whose components are each either the same expression for every member (`0`,
//! `L`) or a bare subscripted name (`x[i]`, `y[i,j]`) — is analysed once: the components
//! that are the same are lowered once, and for each member only the subscripted names are
//! resolved, through the same scope [`pdyn_expr::lower::lower`] resolves them through (so the
//! member names the same expressions it would have lowered to, id for id). Anything else
//! (index arithmetic in a component, `x[i+1] - x[i]`, a name that does not resolve to a
//! scalar) is lowered member by member as before, so its errors are the ones it had.

use pdyn_expr::lower::{lower, Binding, Scope};
use pdyn_expr::syntax::Ast;
use pdyn_expr::{Id, Pool, Value};

/// One component of a template.
#[derive(Debug)]
enum Part {
    /// The same expression for every member.
    Same(Id),
    /// A subscripted name, resolved for each member (`x[i]` → `x[3]`).
    Name(String),
}

/// The template of one field: a vector's components, or one scalar.
#[derive(Debug)]
pub(crate) struct MemberTemplate {
    vector: bool,
    parts: Vec<Part>,
}

impl MemberTemplate {
    /// The template of `ast`, or `None` when it is not of the shape above. `varies` tells
    /// whether a subtree names something that differs from member to member (an index, a
    /// subscripted name, a table's column). The parts that do not vary are lowered here,
    /// through `scope` (with the first member's indices bound: they name none of them).
    pub fn of(
        pool: &mut Pool,
        ast: &Ast,
        scope: &mut dyn Scope,
        varies: &dyn Fn(&Ast) -> bool,
    ) -> Option<MemberTemplate> {
        let (vector, items): (bool, &[Ast]) = match ast {
            // The vector's own checks (two or three components) are `lower`'s.
            Ast::Vector { items, .. } if (2..=3).contains(&items.len()) => (true, items),
            Ast::Vector { .. } => return None,
            other => (false, std::slice::from_ref(other)),
        };
        let mut parts = Vec::with_capacity(items.len());
        let mut any_name = false;
        for item in items {
            match item {
                Ast::Ident { name, .. } if name.contains('[') => {
                    any_name = true;
                    parts.push(Part::Name(name.clone()));
                }
                _ if varies(item) => return None,
                _ => match lower(pool, item, scope) {
                    Ok(Value::Scalar(id)) => parts.push(Part::Same(id)),
                    // A vector where a scalar belongs, or an error: `lower` of the whole
                    // text says so, member by member.
                    _ => return None,
                },
            }
        }
        any_name.then_some(MemberTemplate { vector, parts })
    }

    /// The member's value: each name resolved as `lower` resolves an identifier. `None` when
    /// one does not resolve to a scalar (undefined, outside its family, a vector): the text
    /// is then lowered in full, which reports it.
    pub fn member(&self, pool: &mut Pool, scope: &mut dyn Scope) -> Option<Value> {
        let mut c = [Pool::ZERO; 3];
        for (slot, part) in c.iter_mut().zip(&self.parts) {
            *slot = match part {
                Part::Same(id) => *id,
                Part::Name(name) => match scope.resolve(pool, name)? {
                    Binding::Value(Value::Scalar(id)) => id,
                    Binding::Coordinate(s) => pool.coord(s, 0),
                    Binding::Value(Value::Vector(_)) => return None,
                },
            };
        }
        Some(if self.vector {
            Value::Vector(c)
        } else {
            Value::Scalar(c[0])
        })
    }
}

/// The total time derivative of a member's component, as [`Pool::dt`] makes it: a
/// coordinate's is its next derivative, made directly (a particle family's positions are
/// coordinates: three memoised derivations per member were a sixth of reading them).
pub(crate) fn dt(pool: &mut Pool, e: Id) -> Id {
    match *pool.node(e) {
        pdyn_expr::Node::Coord(s, k) => pool.coord(s, k.saturating_add(1)),
        _ => pool.dt(e),
    }
}
