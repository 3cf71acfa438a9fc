"""SymPy expressions as pdyn's expression text, for the model builder and :func:`pdyn.kin`.

SymPy's own ``str`` is not pdyn's language: ``Abs``, ``E``, ``Derivative(q(t), t)``,
``Piecewise``, ``Heaviside``, ``Max(a, b, c)`` and matrices need translating, and what pdyn
cannot express (complex numbers, infinities, conditions joined by And/Or) is refused with a
``TypeError`` naming it rather than passed on as text that fails later or means something
else.
"""

from __future__ import annotations

from typing import Any


def to_pdyn_text(expr: Any) -> str:
    """``expr`` (a SymPy expression or a 3-vector ``Matrix``) in pdyn's expression syntax."""
    import sympy
    from sympy.core.function import AppliedUndef
    from sympy.printing.str import StrPrinter

    class Printer(StrPrinter):
        def _print_Pow(self, e, rational=False):
            base, exp = e.args
            if exp == sympy.Rational(1, 2):
                return f"sqrt({self._print(base)})"
            if exp == -1:
                return f"1/({self._print(base)})"
            return f"({self._print(base)})^({self._print(exp)})"

        def _print_Abs(self, e):
            return f"abs({self._print(e.args[0])})"

        def _print_Exp1(self, e):
            return "exp(1)"

        def _print_exp(self, e):
            return f"exp({self._print(e.args[0])})"

        def _print_ImaginaryUnit(self, e):
            raise TypeError("pdyn expressions are real: the imaginary unit I has no meaning "
                            "here (a parameter named I is sympy.Symbol('I'))")

        def _print_Infinity(self, e):
            raise TypeError("pdyn expressions are finite: oo has no value")

        _print_NegativeInfinity = _print_ComplexInfinity = _print_NaN = _print_Infinity

        def _print_Function(self, e):
            if isinstance(e, AppliedUndef):
                # q(t) from dynamicsymbols: the coordinate q.
                return e.func.__name__
            return super()._print_Function(e)

        def _print_Derivative(self, e):
            f = e.expr
            if isinstance(f, AppliedUndef) and all(v.name == "t" for v, _ in e.variable_count):
                order = sum(n for _, n in e.variable_count)
                if order <= 2:
                    return f.func.__name__ + "'" * order
            raise TypeError(f"{e}: pdyn writes the rates of coordinates as q' and q'' (first "
                            "and second derivatives in t of a function of t)")

        def _print_Heaviside(self, e):
            return f"((1 + sign({self._print(e.args[0])}))/2)"

        def _minmax(self, e, name):
            args = [self._print(a) for a in e.args]
            out = args[-1]
            for a in reversed(args[:-1]):
                out = f"{name}({a}, {out})"
            return out

        def _print_Max(self, e):
            return self._minmax(e, "max")

        def _print_Min(self, e):
            return self._minmax(e, "min")

        def _print_Piecewise(self, e):
            # Each condition `a > b` (or <, >=, <=) becomes a step (1 + sign(a - b))/2: the
            # branches agree with SymPy's everywhere but on the boundary itself, where the
            # step is 1/2 (a set of measure zero for the integrator).
            *branches, (last, cond) = e.args
            if cond is not sympy.true:
                raise TypeError(f"{e}: a Piecewise needs a last branch with condition True "
                                "(its value where no condition holds)")
            out = self._print(last)
            for value, c in reversed(branches):
                out = f"({self._step(c, e)}*({self._print(value)} - ({out})) + ({out}))"
            return out

        def _step(self, c, whole):
            rel = {sympy.StrictGreaterThan: 1, sympy.GreaterThan: 1,
                   sympy.StrictLessThan: -1, sympy.LessThan: -1}
            for kind, sgn in rel.items():
                if isinstance(c, kind):
                    d = c.lhs - c.rhs if sgn > 0 else c.rhs - c.lhs
                    return f"((1 + sign({self._print(d)}))/2)"
            raise TypeError(f"{whole}: pdyn turns conditions a > b, a < b, a >= b, a <= b into "
                            f"steps; `{c}` is not one of them")

        def _print_MatrixBase(self, e):
            if 3 not in e.shape or 1 not in e.shape:
                raise TypeError(f"a {e.shape[0]}x{e.shape[1]} matrix is not a 3-vector")
            return "[" + ", ".join(self._print(c) for c in e) + "]"

        _print_ImmutableDenseMatrix = _print_MutableDenseMatrix = _print_MatrixBase

        def _print_Float(self, e):
            return repr(float(e))

    return Printer().doprint(expr)
