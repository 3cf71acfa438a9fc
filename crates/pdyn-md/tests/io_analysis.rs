//! File formats round-trip and reject malformed input with line numbers; g(r) of a perfect
//! fcc lattice has 12 neighbours at a/√2; the MSD follows particles across boundaries.

mod common;
use common::*;
use pdyn_md::analysis::{Msd, Rdf};
use pdyn_md::io::*;
use pdyn_md::*;

#[test]
fn extended_xyz_round_trips_exactly() {
    let mut sim = lj_liquid(4, 2, 0.005);
    sim.run(50, &mut |_: &ThermoRecord, _: &System| {}).unwrap();
    let mut buf = vec![];
    write_xyz(&mut buf, &sim.system, &["Ar"], 50, 0.25).unwrap();
    let text = String::from_utf8(buf.clone()).unwrap();
    assert!(text
        .lines()
        .nth(1)
        .unwrap()
        .contains("Properties=species:S:1:pos:R:3:velo:R:3"));
    let f = read_xyz(&buf[..], 1 << 20, 1.0).unwrap();
    assert_eq!(f.names, vec!["Ar".to_string()]);
    assert_eq!(f.system.particles, {
        let mut p = sim.system.particles.clone();
        p.clear_acc();
        p
    });
    assert_eq!(f.system.sim_box, sim.system.sim_box);
    // truncated file: typed error with the line number
    let cut: String = text.lines().take(10).map(|l| format!("{l}\n")).collect();
    assert!(matches!(
        read_xyz(cut.as_bytes(), 1 << 20, 1.0),
        Err(MdError::Parse { line: 11, .. })
    ));
    // a count beyond the limit is refused before allocating
    assert!(matches!(
        read_xyz(&buf[..], 10, 1.0),
        Err(MdError::Particle(_))
    ));
}

#[test]
fn lammps_data_round_trips_and_parses_a_hand_written_file() {
    let sim = lj_liquid(4, 2, 0.005);
    let mut buf = vec![];
    write_lammps_data(&mut buf, &sim.system).unwrap();
    let s = read_lammps_data(&buf[..], 1 << 20).unwrap();
    let mut p = sim.system.particles.clone();
    p.clear_acc();
    assert_eq!(s.particles, p);
    let text = "\
# hand-written
3 atoms
2 atom types
-1.0 4.0 xlo xhi
0 5 ylo yhi
0 5 zlo zhi
0 0 0 xy xz yz

Masses

1 1.0
2 2.5

Pair Coeffs # lj/cut

1 1.0 1.0
2 1.0 1.0

Atoms # atomic

2 2 0.0 1.0 1.0 0 0 0
1 1 1.0 2.0 3.0 0 1 0
3 1 2.0 2.0 2.0 0 0 0

Velocities

1 0.1 0.2 0.3
2 0 0 0
3 0 0 -1
";
    let s = read_lammps_data(text.as_bytes(), 100).unwrap();
    assert_eq!(s.particles.len(), 3);
    assert_eq!(s.types, vec![0, 1, 0]);
    assert_eq!(s.particles.pos(1), Vec3::new(1.0, 1.0, 1.0)); // shifted by xlo = −1
    assert_eq!(s.particles.m[1], 2.5);
    assert_eq!(s.particles.vel(0), Vec3::new(0.1, 0.2, 0.3));
    assert_eq!(s.images[0], [0, 1, 0]);
    let bad = text.replace("3 1 2.0 2.0 2.0 0 0 0", "3 1 2.0 two 2.0 0 0 0");
    assert!(matches!(
        read_lammps_data(bad.as_bytes(), 100),
        Err(MdError::Parse { line: 23, .. })
    ));
    let bad = text.replace("3 1 2.0", "7 1 2.0");
    assert!(matches!(
        read_lammps_data(bad.as_bytes(), 100),
        Err(MdError::InvalidInput { line: 23, .. })
    ));
}

#[test]
fn rdf_of_fcc_counts_twelve_nearest_neighbours() {
    let rho = 0.8442;
    let (p, bx) = lattice(Lattice::Fcc, rho, [6; 3], 1.0, 10_000).unwrap();
    let s = System::new(p, bx);
    let mut rdf = Rdf::new(1.5, 150).unwrap();
    rdf.add(&s).unwrap();
    let (r, g) = rdf.result();
    let dr = 0.01;
    let a = libm::cbrt(4.0 / rho);
    // coordination number ∫ ρ 4π r² g dr over the first shell
    let cn: f64 = r
        .iter()
        .zip(&g)
        .filter(|(r, _)| **r < 0.85 * a)
        .map(|(r, g)| rho * 4.0 * std::f64::consts::PI * r * r * g * dr)
        .sum();
    assert!((cn - 12.0).abs() < 0.05, "{cn}");
    let peak = r[g
        .iter()
        .enumerate()
        .max_by(|x, y| x.1.total_cmp(y.1))
        .unwrap()
        .0];
    assert!((peak - a / 2f64.sqrt()).abs() < 0.01);
    assert!(Rdf::new(1.5, 10)
        .unwrap()
        .add(&System::new(
            lattice(Lattice::Fcc, rho, [2; 3], 1.0, 100).unwrap().0,
            SimBox::cube(2.0).unwrap()
        ))
        .is_err());
}

#[test]
fn msd_follows_particles_across_boundaries() {
    let mut sim = lj_liquid(4, 6, 0.005);
    let msd = Msd::new(&sim.system);
    let n = sim.system.particles.len();
    let mut prev: Vec<Vec3> = (0..n).map(|i| sim.system.particles.pos(i)).collect();
    let mut acc = vec![Vec3::ZERO; n];
    for _ in 0..400 {
        sim.run(1, &mut |_: &ThermoRecord, _: &System| {}).unwrap();
        for i in 0..n {
            let r = sim.system.particles.pos(i);
            acc[i] += sim.system.sim_box.delta(r, prev[i]);
            prev[i] = r;
        }
    }
    let direct = acc.iter().map(|d| d.norm2()).sum::<f64>() / n as f64;
    let m = msd.value(&sim.system);
    assert!((m - direct).abs() < 1e-9 * direct, "{m} vs {direct}");
    assert!(sim.system.images.iter().any(|im| *im != [0, 0, 0]));
    assert!(m > 0.1, "{m}");
}

#[test]
fn rdf_block_error_of_two_blocks_is_half_their_difference() {
    use pdyn_md::analysis::Rdf;
    let a = lj_liquid(4, 2, 0.005);
    let mut b = lj_liquid(4, 2, 0.005);
    b.run(50, &mut |_: &ThermoRecord, _: &System| {}).unwrap();
    let r_max = 0.5 * a.system.sim_box.min_edge() * 0.999;
    let (mut ha, mut hb) = (Rdf::new(r_max, 30).unwrap(), Rdf::new(r_max, 30).unwrap());
    ha.add(&a.system).unwrap();
    hb.add(&b.system).unwrap();
    let (ga, gb) = (ha.result().1, hb.result().1);
    let res = Rdf::block_result(&[ha, hb, Rdf::new(r_max, 30).unwrap()]).unwrap();
    assert_eq!((res.blocks, res.frames), (2, 2));
    let e = res.error.unwrap();
    for k in 0..30 {
        // two blocks: √(((g₁ − m)² + (g₂ − m)²)/2) = |g₁ − g₂|/2; the mean of equal frames
        assert!((e[k] - 0.5 * (ga[k] - gb[k]).abs()).abs() < 1e-12);
        assert!((res.g[k] - 0.5 * (ga[k] + gb[k])).abs() < 1e-12);
    }
    assert!(e.iter().any(|&x| x > 0.0));
}
