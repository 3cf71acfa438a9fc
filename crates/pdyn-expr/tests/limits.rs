//! Exact numbers of any size within the budget, and inputs that used to be quadratic or
//! unbounded: the results are exact and the limits are typed errors. No wall-time assertion.

use pdyn_expr::{Node, Number, Pool};

#[test]
fn numbers_past_64_bits_stay_exact() {
    let mut p = Pool::new();
    // Once 0: the i64 rationals silently became floats.
    assert_eq!(p.parse_scalar("2^64 + 1 - 2^64").unwrap(), Pool::ONE);
    let e = p.parse_scalar("(2/3)^200").unwrap();
    let Some(Number::Rat(r)) = p.as_num(e) else {
        panic!("(2/3)^200 is not exact: {}", p.to_text(e))
    };
    assert_eq!(r.numer_big(), num_bigint::BigInt::from(2).pow(200));
    assert_eq!(r.denom_big(), num_bigint::BigInt::from(3).pow(200));
    // Printed exactly, and the text reads back to the same number.
    let text = p.to_text(e);
    assert_eq!(p.parse_scalar(&text).unwrap(), e);
    // 2^100000 is within the budget: all 30,103 digits.
    let big = p.parse_scalar("2^100000").unwrap();
    let digits = p.to_text(big);
    assert_eq!(digits.len(), 30_103);
    assert!(digits.starts_with("9990020930143845079440327643300335909804291390541816917715292"));
    // Literals too: the Boltzmann constant is 13806503/10^30, printed as written.
    let k = p.parse_scalar("1.3806503e-23*T").unwrap();
    assert_eq!(p.to_text(k), "1.3806503e-23*T");
}

#[test]
fn numbers_over_the_budget_are_refused_with_the_limit() {
    let mut p = Pool::new();
    for src in [
        "2^1000000",
        "(3/7)^-400000",
        "2^300000*2^300000",
        "1e200000",
        "10^99999999999999999999",
    ] {
        let err = p.parse_scalar(src).expect_err(src);
        assert!(
            err.message.contains("100000 digits"),
            "{src}: {}",
            err.message
        );
    }
}

/// Runs `f` on a thread with a small stack: deep recursion would overflow it.
fn small_stack(f: impl FnOnce() + Send + 'static) {
    std::thread::Builder::new()
        .stack_size(256 * 1024)
        .spawn(f)
        .unwrap()
        .join()
        .unwrap();
}

#[test]
fn long_sums_and_products_are_near_linear_and_shallow() {
    small_stack(|| {
        let n = 20_000;
        let src: Vec<String> = (0..n).map(|i| format!("a{i}")).collect();
        let mut p = Pool::new();
        let before = p.len();
        let s = p.parse_scalar(&src.join(" + ")).unwrap();
        let Node::Add(ts) = p.node(s) else {
            panic!("not a sum")
        };
        assert_eq!(ts.len(), n);
        // One sum node and the symbols: no quadratic trail of partial sums.
        assert!(p.len() - before <= n + 2, "{} nodes", p.len() - before);
        let back = p.to_text(s);
        assert_eq!(p.parse_scalar(&back).unwrap(), s);
        // Differences and long products keep their meaning when built as balanced trees.
        let d = p
            .parse_scalar(&format!("{} - a0", src.join(" - ")))
            .unwrap();
        // a0 - a1 - ... - a19999 - a0 = -(a1 + ... + a19999)
        let expected = {
            let rest = p.parse_scalar(&src[1..].join(" + ")).unwrap();
            p.neg(rest)
        };
        assert_eq!(d, expected);
        let q = p
            .parse_scalar(&format!("x*{}/y/z", src[..5000].join("*")))
            .unwrap();
        let r = p
            .parse_scalar(&format!("x/y*{}/z", src[..5000].join("*")))
            .unwrap();
        assert_eq!(q, r);
    });
}

/// A division by zero where it is written is an error at the divisor (or at the power of zero),
/// whatever the divisor looks like before it is put in canonical form; never `1/0` carried on.
#[test]
fn a_division_by_zero_is_an_error_at_the_divisor() {
    for (src, located) in [
        ("1/0", "0"),
        ("x/(x-x)", "(x-x)"),
        ("x/0.0", "0.0"),
        ("sin(t)/(2*y - y - y)", "(2*y - y - y)"),
        ("[1, 2, 3]/(a - a)", "(a - a)"),
        ("1/(0*x)", "(0*x)"),
        ("1/sin(0)", "sin(0)"),
        ("x + 3/(t^2 - t*t)", "(t^2 - t*t)"),
        ("0^-1", "0^-1"),
        ("(x - x)^(-2)", "(x - x)^(-2)"),
        ("(y-y)^(-1/2)", "(y-y)^(-1/2)"),
    ] {
        let mut p = Pool::new();
        let err = p.parse_scalar(src).expect_err(src);
        assert!(
            err.message.contains("division by zero"),
            "{src}: {}",
            err.message
        );
        assert_eq!(&src[err.span.clone()], located, "{src}: {err:?}");
    }
    // Zero in a numerator, a positive power of zero, a divisor that is zero only at some
    // points: all fine.
    let mut p = Pool::new();
    for src in ["0/x", "0^2", "1/x", "1/(x - 1)", "x/(x - y)", "(x-x)^2"] {
        p.parse_scalar(src)
            .unwrap_or_else(|e| panic!("{src}: {e:?}"));
    }
}

/// A division by zero that only simplification reveals is seen by `divides_by_zero` (the
/// check `pdyn simplify` makes on its result); ordinary results are not flagged.
#[test]
fn a_zero_denominator_revealed_by_simplification_is_detected() {
    let mut p = Pool::new();
    for src in [
        "1/((x+1)^2 - x^2 - 2*x - 1)",
        "y + 2/((a-b)^2 - a^2 + 2*a*b - b^2)",
    ] {
        let e = p.parse_scalar(src).unwrap();
        let e = p.expand(e);
        let s = p.simplify(e);
        assert!(p.divides_by_zero(s), "{src} -> {}", p.to_text(s));
    }
    for src in [
        "1/x",
        "1/((x+1)^2 - x^2)",
        "0^2 + 1/(x - 1)",
        "sin(x)/cos(x)",
    ] {
        let e = p.parse_scalar(src).unwrap();
        let e = p.expand(e);
        let s = p.simplify(e);
        assert!(!p.divides_by_zero(s), "{src} -> {}", p.to_text(s));
    }
}

/// A coordinate's derivative order is a byte: 256 primes or more, written or reached by
/// differentiating in time, is an error naming the order, never a saturated `x` with 255
/// primes (which made `x` differentiated 300 times equal to `x` differentiated 255 times).
#[test]
fn time_derivatives_past_order_255_are_refused() {
    let primes = |n: usize| "'".repeat(n);
    let mut p = Pool::new();
    // Up to 255 primes is fine.
    let ok = p.parse_scalar(&format!("x{}", primes(255))).unwrap();
    assert!(matches!(p.node(ok), Node::Coord(_, 255)));
    for src in [
        format!("x{}", primes(256)),
        format!("x{}", primes(300)),
        format!("2*y{} + 1", primes(1000)),
        format!("(x{}){}", primes(200), primes(56)),
        format!("(x{} + t){}", primes(255), primes(1)),
    ] {
        let err = p.parse_scalar(&src).expect_err(&src);
        assert!(err.message.contains("255"), "{}", err.message);
        assert!(!err.span.is_empty() && src[err.span.clone()].contains('\''));
    }
    // Differentiating in time past the order is a budget error; `t^2` has no coordinate.
    for (src, n) in [("x(t)", 256usize), ("x''", 254), ("sin(x(t))*y'", 255)] {
        let e = p.parse_scalar(src).unwrap();
        let err = p.try_derivative_n(e, None, n).expect_err(src);
        assert!(
            matches!(err, pdyn_expr::budget::BudgetError::CoordinateOrder { .. }),
            "{src}: {err:?}"
        );
    }
    let x = p.parse_scalar("x(t)").unwrap();
    let d = p.try_derivative_n(x, None, 255).unwrap();
    assert!(matches!(p.node(d), Node::Coord(_, 255)));
    let t2 = p.parse_scalar("t^2").unwrap();
    assert_eq!(p.try_derivative_n(t2, None, 1000).unwrap(), Pool::ZERO);
}
