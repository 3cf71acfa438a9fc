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
