//! The expression pool: an arena of hash-consed, immutable nodes.
//!
//! Every expression is an [`Id`] into a [`Pool`]. A node holds the ids of its children, and the
//! pool interns nodes, so structurally identical subexpressions are stored once and compare
//! equal by id in O(1). Nodes are only created through the canonicalising constructors in
//! [`crate::build`], which keeps every stored node in canonical form (flattened sums and
//! products, collected like terms, folded constants, deterministic child order).

use crate::number::Number;
use rustc_hash::FxHashMap;
use std::cmp::Ordering;

/// Handle of an expression node in a [`Pool`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Id(pub(crate) u32);

impl Id {
    /// Position of the node in its pool (creation order: children come before parents).
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Handle of a named symbol (parameter or coordinate) in a [`Pool`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SymId(pub(crate) u32);

/// Mathematical constants with their own node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Constant {
    /// π
    Pi,
    /// Euler's number e
    E,
}

impl Constant {
    /// Numeric value.
    pub fn value(self) -> f64 {
        match self {
            Constant::Pi => std::f64::consts::PI,
            Constant::E => std::f64::consts::E,
        }
    }
}

/// Built-in scalar functions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[allow(missing_docs)]
pub enum Func {
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
    Abs,
    Sign,
    Min,
    Max,
    /// A tabulated function (measured data) or one of its derivatives: see
    /// [`crate::tabulated`]. Its name is the pool's ([`Pool::table_fn_name`]).
    Table(crate::tabulated::TableFn),
}

impl Func {
    /// Every function, for name lookup and suggestions.
    pub const ALL: [Func; 16] = [
        Func::Sin,
        Func::Cos,
        Func::Tan,
        Func::Asin,
        Func::Acos,
        Func::Atan,
        Func::Atan2,
        Func::Sinh,
        Func::Cosh,
        Func::Tanh,
        Func::Exp,
        Func::Log,
        Func::Abs,
        Func::Sign,
        Func::Min,
        Func::Max,
    ];
    /// The name used in the expression language.
    pub fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Asin => "asin",
            Func::Acos => "acos",
            Func::Atan => "atan",
            Func::Atan2 => "atan2",
            Func::Sinh => "sinh",
            Func::Cosh => "cosh",
            Func::Tanh => "tanh",
            Func::Exp => "exp",
            Func::Log => "log",
            Func::Abs => "abs",
            Func::Sign => "sign",
            Func::Min => "min",
            Func::Max => "max",
            Func::Table(_) => "data",
        }
    }
    /// Number of arguments.
    pub fn arity(self) -> usize {
        match self {
            Func::Atan2 | Func::Min | Func::Max => 2,
            _ => 1,
        }
    }
    /// Look a function up by name.
    pub fn from_name(name: &str) -> Option<Func> {
        Func::ALL.iter().copied().find(|f| f.name() == name)
    }
}

/// A node's parts, borrowed: what the node table hashes and compares, so that a lookup needs
/// no allocated node (most lookups find one).
#[derive(PartialEq, Hash)]
pub(crate) enum NodeRef<'a> {
    Num(&'a Number),
    Const(Constant),
    Time,
    Sym(SymId),
    Coord(SymId, u8),
    Add(&'a [Id]),
    Mul(&'a [Id]),
    Pow(Id, Id),
    Call(Func, &'a [Id]),
}

impl Node {
    pub(crate) fn parts(&self) -> NodeRef<'_> {
        match self {
            Node::Num(n) => NodeRef::Num(n),
            Node::Const(c) => NodeRef::Const(*c),
            Node::Time => NodeRef::Time,
            Node::Sym(s) => NodeRef::Sym(*s),
            Node::Coord(s, k) => NodeRef::Coord(*s, *k),
            Node::Add(ts) => NodeRef::Add(ts),
            Node::Mul(fs) => NodeRef::Mul(fs),
            Node::Pow(b, e) => NodeRef::Pow(*b, *e),
            Node::Call(f, args) => NodeRef::Call(*f, args),
        }
    }
}

fn parts_hash(r: &NodeRef<'_>) -> u64 {
    use std::hash::BuildHasher;
    rustc_hash::FxBuildHasher.hash_one(r)
}

/// One node of the expression DAG.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    /// A number.
    Num(Number),
    /// π or e.
    Const(Constant),
    /// Time `t`.
    Time,
    /// A constant symbol (parameter).
    Sym(SymId),
    /// A coordinate (unknown function of time) differentiated `order` times: `x`, `x'`, `x''`.
    Coord(SymId, u8),
    /// Sum of at least two terms, canonically ordered; a numeric term comes first.
    Add(Box<[Id]>),
    /// Product of at least two factors, canonically ordered; a numeric coefficient comes first.
    Mul(Box<[Id]>),
    /// `base ^ exponent`.
    Pow(Id, Id),
    /// A function call.
    Call(Func, Box<[Id]>),
}

/// What is known about a symbol.
#[derive(Clone, Debug)]
pub struct Symbol {
    /// Its name.
    pub name: String,
    /// Declared strictly positive (masses, lengths, g...): enables `sqrt(x^2) = x`.
    pub positive: bool,
}

/// Arena and interner of expression nodes, plus the symbol table.
#[derive(Clone, Debug)]
pub struct Pool {
    nodes: Vec<Node>,
    /// Every node's id, found by the node's parts (`NodeRef`): each node is stored once, in
    /// `nodes`.
    interned: hashbrown::HashTable<Id>,
    symbols: Vec<Symbol>,
    symbol_ids: FxHashMap<String, SymId>,
    pub(crate) memo: crate::memo::Memo,
    pub(crate) spare: crate::build::Spare,
    /// Tabulated functions callable by name (`crate::tabulated`).
    pub(crate) tables: Vec<crate::tabulated::TableEntry>,
}

impl Default for Pool {
    fn default() -> Self {
        Pool::new()
    }
}

impl Pool {
    /// An empty pool holding the constants 0, 1, -1.
    pub fn new() -> Pool {
        let mut p = Pool {
            nodes: Vec::new(),
            interned: hashbrown::HashTable::new(),
            symbols: Vec::new(),
            symbol_ids: FxHashMap::default(),
            memo: Default::default(),
            spare: Default::default(),
            tables: Vec::new(),
        };
        p.intern(Node::Num(Number::ZERO));
        p.intern(Node::Num(Number::ONE));
        p.intern(Node::Num(Number::MINUS_ONE));
        p
    }

    /// The expression `0`.
    pub const ZERO: Id = Id(0);
    /// The expression `1`.
    pub const ONE: Id = Id(1);
    /// The expression `-1`.
    pub const MINUS_ONE: Id = Id(2);

    /// Interns a node that is already canonical. Use the constructors in [`crate::build`].
    pub(crate) fn intern(&mut self, node: Node) -> Id {
        let hash = parts_hash(&node.parts());
        match self.find_or_vacant(hash, &node.parts()) {
            Ok(id) => id,
            Err(()) => self.push_new(hash, node),
        }
    }

    /// Interns the node with these parts (already canonical), allocating it only when it is
    /// new: a sum's or product's terms come from a reused buffer, and most lookups of a long
    /// derivation find the node.
    pub(crate) fn intern_parts(&mut self, parts: NodeRef<'_>) -> Id {
        let hash = parts_hash(&parts);
        if let Ok(id) = self.find_or_vacant(hash, &parts) {
            return id;
        }
        let node = match parts {
            NodeRef::Add(ts) => Node::Add(ts.into()),
            NodeRef::Mul(fs) => Node::Mul(fs.into()),
            NodeRef::Call(f, args) => Node::Call(f, args.into()),
            NodeRef::Num(n) => Node::Num(n.clone()),
            NodeRef::Const(c) => Node::Const(c),
            NodeRef::Time => Node::Time,
            NodeRef::Sym(s) => Node::Sym(s),
            NodeRef::Coord(s, k) => Node::Coord(s, k),
            NodeRef::Pow(b, e) => Node::Pow(b, e),
        };
        self.push_new(hash, node)
    }

    /// The id of the node with these parts, if interned.
    fn find_or_vacant(&self, hash: u64, parts: &NodeRef<'_>) -> Result<Id, ()> {
        self.interned
            .find(hash, |&id| self.nodes[id.index()].parts() == *parts)
            .copied()
            .ok_or(())
    }

    /// Stores a node known not to be interned.
    fn push_new(&mut self, hash: u64, node: Node) -> Id {
        let id = Id(self.nodes.len() as u32);
        self.nodes.push(node);
        let nodes = &self.nodes;
        self.interned
            .insert_unique(hash, id, |&k| parts_hash(&nodes[k.index()].parts()));
        id
    }

    /// The node behind an id.
    pub fn node(&self, id: Id) -> &Node {
        &self.nodes[id.index()]
    }

    /// Number of distinct nodes stored.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// True when only the built-in constants are stored.
    pub fn is_empty(&self) -> bool {
        self.nodes.len() <= 3
    }

    /// The symbol named `name`, created if new. Positivity is kept from the first declaration
    /// unless `positive` is true.
    pub fn symbol(&mut self, name: &str, positive: bool) -> SymId {
        if let Some(&s) = self.symbol_ids.get(name) {
            if positive {
                self.symbols[s.0 as usize].positive = true;
            }
            return s;
        }
        let s = SymId(self.symbols.len() as u32);
        self.symbols.push(Symbol {
            name: name.to_string(),
            positive,
        });
        self.symbol_ids.insert(name.to_string(), s);
        s
    }

    /// Looks a symbol up without creating it.
    pub fn find_symbol(&self, name: &str) -> Option<SymId> {
        self.symbol_ids.get(name).copied()
    }

    /// Information about a symbol.
    pub fn symbol_info(&self, s: SymId) -> &Symbol {
        &self.symbols[s.0 as usize]
    }

    /// Marks a symbol as strictly positive (affects expressions built afterwards).
    pub fn assume_positive(&mut self, s: SymId) {
        self.symbols[s.0 as usize].positive = true;
    }

    /// Name of a symbol.
    pub fn name(&self, s: SymId) -> &str {
        &self.symbols[s.0 as usize].name
    }

    /// The expression for a constant symbol.
    pub fn sym(&mut self, s: SymId) -> Id {
        self.intern(Node::Sym(s))
    }

    /// Shorthand: the expression for the symbol named `name` (created if new).
    pub fn var(&mut self, name: &str) -> Id {
        let s = self.symbol(name, false);
        self.sym(s)
    }

    /// The expression for coordinate `s` differentiated `order` times.
    pub fn coord(&mut self, s: SymId, order: u8) -> Id {
        self.intern(Node::Coord(s, order))
    }

    /// The expression `t`.
    pub fn time(&mut self) -> Id {
        self.intern(Node::Time)
    }

    /// The expression for a number.
    pub fn num(&mut self, n: Number) -> Id {
        let n = match n {
            Number::Float(0.0) => Number::ZERO,
            other => other,
        };
        self.intern(Node::Num(n))
    }

    /// The expression for an integer.
    pub fn int(&mut self, n: i64) -> Id {
        self.num(Number::int(n))
    }

    /// The expression for π or e.
    pub fn constant(&mut self, c: Constant) -> Id {
        self.intern(Node::Const(c))
    }

    /// The number, when `id` is a numeric constant.
    pub fn as_num(&self, id: Id) -> Option<Number> {
        match self.node(id) {
            Node::Num(n) => Some(n.clone()),
            _ => None,
        }
    }

    /// True when `id` is the exact number zero.
    pub fn is_zero(&self, id: Id) -> bool {
        id == Pool::ZERO
    }

    /// The highest order of a coordinate in `id` (0 when it has none or only `x`).
    pub fn max_coord_order(&self, id: Id) -> usize {
        let mut order = 0;
        self.visit_once(id, |n| {
            if let Node::Coord(_, k) = n {
                order = order.max(*k as usize);
            }
        });
        order
    }

    /// Whether `id` contains a coordinate (`x`, `x'`, …).
    pub fn has_coord(&self, id: Id) -> bool {
        let mut found = false;
        self.visit_once(id, |n| found |= matches!(n, Node::Coord(..)));
        found
    }

    /// Calls `f` on every node of `id` once (the expression is a DAG).
    fn visit_once(&self, id: Id, mut f: impl FnMut(&Node)) {
        let mut seen = rustc_hash::FxHashSet::default();
        let mut stack = vec![id];
        while let Some(x) = stack.pop() {
            if seen.insert(x) {
                f(self.node(x));
                self.for_each_child(x, |c| stack.push(c));
            }
        }
    }

    /// Whether `id` contains a division by zero: a power of the number zero with a negative
    /// exponent (`1/0`), or a number that is not finite (expansion folds `1/0` into an
    /// infinite float), as simplification can leave them (`1/((x+1)^2 - x^2 - 2*x - 1)`).
    pub fn divides_by_zero(&self, id: Id) -> bool {
        let mut found = false;
        self.visit_once(id, |n| {
            found |= match n {
                Node::Pow(b, e) => {
                    matches!(self.node(*b), Node::Num(n) if n.is_zero())
                        && matches!(self.node(*e), Node::Num(n) if n.is_negative())
                }
                Node::Num(Number::Float(f)) => !f.is_finite(),
                _ => false,
            }
        });
        found
    }

    /// Calls `f` on each child of `id`.
    pub fn for_each_child(&self, id: Id, mut f: impl FnMut(Id)) {
        match self.node(id) {
            Node::Add(c) | Node::Mul(c) | Node::Call(_, c) => c.iter().for_each(|&x| f(x)),
            Node::Pow(b, e) => {
                f(*b);
                f(*e);
            }
            _ => {}
        }
    }

    /// True if `needle` occurs anywhere in `hay`.
    pub fn contains(&self, hay: Id, needle: Id) -> bool {
        let mut seen = rustc_hash::FxHashSet::default();
        let mut stack = vec![hay];
        while let Some(x) = stack.pop() {
            if x == needle {
                return true;
            }
            if x.0 < needle.0 || !seen.insert(x) {
                // Children are always older than parents: nothing below `x` can be `needle`.
                continue;
            }
            self.for_each_child(x, |c| stack.push(c));
        }
        false
    }

    /// True if any of `needles` occurs in any of `hays`: one traversal of their shared DAG,
    /// where calling [`Pool::contains`] for every pair costs hays × needles traversals (the
    /// 100-link chain's 10,100 matrix entries against its 100 rates took a quarter of
    /// `pdyn run`'s preparation).
    pub fn contains_any(&self, hays: &[Id], needles: &[Id]) -> bool {
        let wanted: rustc_hash::FxHashSet<Id> = needles.iter().copied().collect();
        let Some(oldest) = needles.iter().min() else {
            return false;
        };
        let mut seen = rustc_hash::FxHashSet::default();
        let mut stack: Vec<Id> = hays.to_vec();
        while let Some(x) = stack.pop() {
            if wanted.contains(&x) {
                return true;
            }
            if x.0 < oldest.0 || !seen.insert(x) {
                // Children are always older than parents: nothing below `x` is a needle.
                continue;
            }
            self.for_each_child(x, |c| stack.push(c));
        }
        false
    }

    /// The members of `needles` that occur in `hay`, in one traversal of its DAG (asking
    /// [`Pool::contains`] for each needle costs one traversal per needle: the equations of a
    /// net of N particles against its 3N accelerations made that quadratic).
    ///
    /// Subtrees older than every needle are skipped, but only when the set is small: finding
    /// its oldest member reads the whole set, and callers ask about each of a net's N rows
    /// against its 2N coordinates and rates (quadratic: 29 % of `pdyn modes` on a chain of
    /// 10⁴ masses). A small hay is cheaper to walk whole than a large set to scan.
    pub fn occurring(&self, hay: Id, needles: &rustc_hash::FxHashSet<Id>) -> Vec<Id> {
        const SCAN_AT_MOST: usize = 64;
        if needles.is_empty() {
            return Vec::new();
        }
        let oldest = if needles.len() <= SCAN_AT_MOST {
            needles.iter().min().copied().unwrap_or(Id(0))
        } else {
            Id(0)
        };
        let mut found = Vec::new();
        let mut seen = rustc_hash::FxHashSet::default();
        let mut stack = vec![hay];
        while let Some(x) = stack.pop() {
            if x.0 < oldest.0 || !seen.insert(x) {
                // Children are always older than parents: nothing below `x` is a needle.
                continue;
            }
            if needles.contains(&x) {
                found.push(x);
            }
            self.for_each_child(x, |c| stack.push(c));
        }
        found
    }

    /// True if any node in `hay` satisfies `pred`.
    pub fn any_node(&self, hay: Id, pred: &dyn Fn(&Node) -> bool) -> bool {
        let mut seen = rustc_hash::FxHashSet::default();
        let mut stack = vec![hay];
        while let Some(x) = stack.pop() {
            if !seen.insert(x) {
                continue;
            }
            if pred(self.node(x)) {
                return true;
            }
            self.for_each_child(x, |c| stack.push(c));
        }
        false
    }

    /// The distinct nodes reachable from `roots`, children before parents.
    pub fn topo_order(&self, roots: &[Id]) -> Vec<Id> {
        self.topo_order_pruned(roots, |_| false)
    }

    /// [`Pool::topo_order`] without the nodes for which `done` is true nor anything only
    /// reachable through them: for a caller that has already handled those (a compiler
    /// emitting 10,100 matrix entries that share most of their subexpressions would otherwise
    /// walk the shared part again for every entry).
    pub fn topo_order_pruned(&self, roots: &[Id], done: impl Fn(Id) -> bool) -> Vec<Id> {
        let mut seen = rustc_hash::FxHashSet::default();
        let mut out = Vec::new();
        let mut stack: Vec<(Id, bool)> = roots.iter().rev().map(|&r| (r, false)).collect();
        while let Some((x, expanded)) = stack.pop() {
            if expanded {
                out.push(x);
                continue;
            }
            if done(x) || !seen.insert(x) {
                continue;
            }
            stack.push((x, true));
            let mut kids = Vec::new();
            self.for_each_child(x, |c| kids.push(c));
            for c in kids.into_iter().rev() {
                if !seen.contains(&c) {
                    stack.push((c, false));
                }
            }
        }
        out
    }

    /// Number of distinct nodes reachable from `roots` (the DAG size).
    pub fn dag_size(&self, roots: &[Id]) -> usize {
        self.topo_order(roots).len()
    }

    /// Size of the expression written out as a tree (shared nodes counted each time),
    /// saturating at `cap`. Used as the cost in `simplify`.
    pub fn tree_size(&self, id: Id, cap: usize) -> usize {
        let mut n = 0usize;
        let mut stack = vec![id];
        while let Some(x) = stack.pop() {
            n += match self.node(x) {
                // Small integers and leaves cost 1; a non-integer coefficient a bit more.
                Node::Num(Number::Rat(r)) if !r.is_integer() => 2,
                _ => 1,
            };
            if n >= cap {
                return cap;
            }
            self.for_each_child(x, |c| stack.push(c));
        }
        n
    }

    /// Canonical order of expressions: numbers, constants, symbols by name, `t`, coordinates
    /// by name then derivative order, then compound nodes. Powers sort with their base so that
    /// `a^2*b` keeps `a` before `b`. Deterministic: depends only on structure and names.
    pub fn order(&self, a: Id, b: Id) -> Ordering {
        // Ties between distinct nodes (possible only for exotic shapes) fall back to the id,
        // which is unique per structure within a pool, so sorting stays canonical.
        self.order_struct(a, b).then(a.cmp(&b))
    }

    fn order_struct(&self, a: Id, b: Id) -> Ordering {
        if a == b {
            return Ordering::Equal;
        }
        // Compare terms by their non-numeric factors first (so `-a` sorts with `a`), then by
        // coefficient.
        let (one_a, one_b) = ([a], [b]);
        let (ca, fa) = self.factor_view(a, &one_a);
        let (cb, fb) = self.factor_view(b, &one_b);
        for (x, y) in fa.iter().zip(fb) {
            let o = self.order_factor(*x, *y);
            if o != Ordering::Equal {
                return o;
            }
        }
        fa.len().cmp(&fb.len()).then_with(|| match (ca, cb) {
            (Some(x), Some(y)) => self.order_plain(x, y),
            (None, Some(_)) => Ordering::Less,
            (Some(_), None) => Ordering::Greater,
            (None, None) => Ordering::Equal,
        })
    }

    /// (numeric coefficient, other factors) of a term; `one` is `[a]`, used for non-products.
    fn factor_view<'a>(&'a self, a: Id, one: &'a [Id; 1]) -> (Option<Id>, &'a [Id]) {
        match self.node(a) {
            Node::Mul(fs) => match self.node(fs[0]) {
                Node::Num(_) => (Some(fs[0]), &fs[1..]),
                _ => (None, &fs[..]),
            },
            Node::Num(_) => (Some(a), &[]),
            _ => (None, one),
        }
    }

    fn order_factor(&self, a: Id, b: Id) -> Ordering {
        if a == b {
            return Ordering::Equal;
        }
        let (ba, ea) = self.base_exp(a);
        let (bb, eb) = self.base_exp(b);
        if ba != bb {
            return self.order_plain(ba, bb);
        }
        match (ea, eb) {
            (None, None) => Ordering::Equal,
            (None, Some(_)) => Ordering::Less,
            (Some(_), None) => Ordering::Greater,
            (Some(x), Some(y)) => self.order_struct(x, y),
        }
    }

    fn base_exp(&self, a: Id) -> (Id, Option<Id>) {
        match self.node(a) {
            Node::Pow(b, e) => (*b, Some(*e)),
            _ => (a, None),
        }
    }

    fn rank(node: &Node) -> u8 {
        match node {
            Node::Num(_) => 0,
            Node::Const(_) => 1,
            Node::Sym(_) => 2,
            Node::Time => 3,
            Node::Coord(..) => 4,
            Node::Call(..) => 5,
            Node::Pow(..) => 6,
            Node::Mul(_) => 7,
            Node::Add(_) => 8,
        }
    }

    fn order_plain(&self, a: Id, b: Id) -> Ordering {
        if a == b {
            return Ordering::Equal;
        }
        let (na, nb) = (self.node(a), self.node(b));
        let r = Pool::rank(na).cmp(&Pool::rank(nb));
        if r != Ordering::Equal {
            return r;
        }
        match (na, nb) {
            (Node::Num(x), Node::Num(y)) => x.total_cmp(y),
            (Node::Const(x), Node::Const(y)) => x.cmp(y),
            (Node::Sym(x), Node::Sym(y)) => self.name(*x).cmp(self.name(*y)),
            (Node::Coord(x, i), Node::Coord(y, j)) => {
                self.name(*x).cmp(self.name(*y)).then(i.cmp(j))
            }
            (Node::Call(f, xs), Node::Call(g, ys)) => {
                f.cmp(g).then_with(|| self.order_lists(xs, ys))
            }
            (Node::Pow(b1, e1), Node::Pow(b2, e2)) => self
                .order_struct(*b1, *b2)
                .then_with(|| self.order_struct(*e1, *e2)),
            (Node::Mul(xs), Node::Mul(ys)) | (Node::Add(xs), Node::Add(ys)) => {
                self.order_lists(xs, ys)
            }
            _ => a.cmp(&b),
        }
    }

    fn order_lists(&self, xs: &[Id], ys: &[Id]) -> Ordering {
        for (x, y) in xs.iter().zip(ys) {
            let o = self.order_struct(*x, *y);
            if o != Ordering::Equal {
                return o;
            }
        }
        xs.len().cmp(&ys.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A node interned from its parts and the same node interned whole get one id, and the
    /// node is stored once.
    #[test]
    fn nodes_are_found_by_their_parts() {
        let mut p = Pool::new();
        let (x, y) = (p.var("x"), p.var("y"));
        let before = p.len();
        let by_parts = p.intern_parts(NodeRef::Add(&[x, y]));
        assert_eq!(p.len(), before + 1);
        let whole = p.intern(Node::Add(Box::new([x, y])));
        assert_eq!(by_parts, whole);
        assert_eq!(p.len(), before + 1);
        // Other kinds and orders are other nodes.
        let product = p.intern_parts(NodeRef::Mul(&[x, y]));
        let reversed = p.intern_parts(NodeRef::Add(&[y, x]));
        assert!(product != by_parts && reversed != by_parts);
        let sin = p.intern_parts(NodeRef::Call(Func::Sin, &[x]));
        assert_eq!(sin, p.intern(Node::Call(Func::Sin, Box::new([x]))));
        assert_eq!(p.len(), before + 4);
        // The canonical constructors meet the same nodes.
        assert_eq!(p.add(&[x, y]), by_parts);
    }

    #[test]
    fn contains_any_agrees_with_contains_on_every_pair() {
        let mut p = Pool::new();
        let exprs: Vec<Id> = [
            "a*sin(x) + b",
            "cos(y)^2*c",
            "a + b + c",
            "exp(z*x) - y",
            "3",
            "x",
        ]
        .iter()
        .map(|s| p.parse_scalar(s).unwrap())
        .collect();
        let leaves: Vec<Id> = ["x", "y", "z", "a", "b", "c", "w"]
            .iter()
            .map(|s| p.parse_scalar(s).unwrap())
            .collect();
        // Every subset of hays against every subset of needles (small enough to enumerate).
        for hmask in 0u32..(1 << exprs.len()) {
            let hays: Vec<Id> = (0..exprs.len())
                .filter(|i| hmask & (1 << i) != 0)
                .map(|i| exprs[i])
                .collect();
            for nmask in 0u32..(1 << leaves.len()) {
                let needles: Vec<Id> = (0..leaves.len())
                    .filter(|i| nmask & (1 << i) != 0)
                    .map(|i| leaves[i])
                    .collect();
                let pairwise = hays
                    .iter()
                    .any(|&h| needles.iter().any(|&n| p.contains(h, n)));
                assert_eq!(p.contains_any(&hays, &needles), pairwise);
            }
        }
    }

    /// `occurring` finds exactly the needles `contains` finds, with few needles (subtrees
    /// older than all of them skipped) and with many (more than it scans for the oldest).
    #[test]
    fn occurring_agrees_with_contains_for_small_and_large_needle_sets() {
        let mut p = Pool::new();
        let many: Vec<Id> = (0..200)
            .map(|k| p.parse_scalar(&format!("v{k}")).unwrap())
            .collect();
        let exprs: Vec<Id> = [
            "a*sin(v3) + v150*b",
            "cos(v199)^2*c + v0",
            "a + b + c",
            "exp(v70*v71) - v72/v73",
            "3",
            "v10",
        ]
        .iter()
        .map(|s| p.parse_scalar(s).unwrap())
        .collect();
        for size in [1, 5, 64, 65, 200] {
            for start in [0, 3, 70, 150] {
                let needles: rustc_hash::FxHashSet<Id> =
                    many.iter().skip(start).take(size).copied().collect();
                for &e in &exprs {
                    let mut found = p.occurring(e, &needles);
                    found.sort();
                    let mut expected: Vec<Id> = needles
                        .iter()
                        .copied()
                        .filter(|&n| p.contains(e, n))
                        .collect();
                    expected.sort();
                    assert_eq!(found, expected, "{size} needles from v{start}");
                }
            }
        }
    }
}
