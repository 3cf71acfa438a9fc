//! A run's conservation scales ride in the output columns' program as its trailing outputs
//! (`Observer::with_trailing`), computed once per row with the columns they share terms with.
//! At any state they must give the bits of the scales' own program, and the columns those
//! the columns alone give.

use super::prepare;
use super::tree_tests::released_chain;

/// Two bodies on a spring, free in space: energy, momentum and angular momentum conserved
/// (several scales, in order).
const TWO_BODIES: &str = r#"
name = "two bodies on a spring"
[parameters]
k = 3.0
[coordinates]
x1 = { initial = 0.1, rate = 0.3 }
y1 = { initial = -0.4, rate = 0.1 }
z1 = { initial = 0.2, rate = -0.2 }
x2 = { initial = 1.3, rate = -0.5 }
y2 = { initial = 0.6, rate = 0.2 }
z2 = { initial = -0.1, rate = 0.4 }
[particles.a]
mass = "1.5"
position = "[x1, y1, z1]"
[particles.b]
mass = "0.7"
position = "[x2, y2, z2]"
[[forces]]
kind = "spring"
between = ["a", "b"]
k = "k"
l0 = "1"
"#;

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// The columns and trailing scales of `source`'s observer against the columns alone and the
/// scales' own program, at seeded states; `min_scales` scales at least.
fn trailing_scales_have_their_own_programs_bits(source: &str, min_scales: usize) {
    let mut model = pdyn_mech::load(source, "m.toml").unwrap();
    let prep = prepare(&mut model).unwrap();
    let (columns, scales) = (prep.observer.len(), prep.scales.len());
    assert!(scales >= min_scales, "{scales} scales");
    assert_eq!(prep.observer.trailing(), scales);
    let n = prep.y0.len();
    let mut x = 0x2545_f491_4f6c_dd1d_u64;
    let (mut input, mut alone, mut own) = (Vec::new(), vec![0.0; columns], vec![0.0; scales]);
    let mut all = vec![0.0; columns + scales];
    for _ in 0..50 {
        let y: Vec<f64> = (0..n)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 8.0
            })
            .collect();
        prep.system.observation_input(0.7, &y, &mut input);
        prep.observer.eval_with_trailing(&input, &mut all);
        prep.observer.eval(&input, &mut alone);
        prep.scales.eval(&input, &mut own);
        assert_eq!(bits(&all[..columns]), bits(&alone));
        assert_eq!(bits(&all[columns..]), bits(&own));
        assert!(own.iter().all(|s| s.is_finite() && *s > 0.0));
    }
}

#[test]
fn two_bodies_scales_in_the_columns_program_have_their_own_bits() {
    trailing_scales_have_their_own_programs_bits(TWO_BODIES, 3);
}

#[test]
fn a_chains_energy_scale_in_the_columns_program_has_its_own_bits() {
    // A four-link chain under gravity (the tree path): energy conserved, its scale
    // `Σ ½ m v² + Σ |V|` made of the energy column's terms.
    trailing_scales_have_their_own_programs_bits(&released_chain(4), 1);
}
