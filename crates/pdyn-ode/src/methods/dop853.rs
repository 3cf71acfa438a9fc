//! **DOP853** — Dormand–Prince 8(5,3), Hairer's high-order explicit code.
//!
//! Explicit, adaptive, 12 stages per step plus `f(t + h, y1)` after an accepted step (reused
//! as the next first stage): 11 new evaluations per attempt, one more per accepted step.
//! Order 8 propagated; the error estimate combines an embedded 5th-order and a 3rd-order
//! solution,
//! ```text
//!   err5 = Σ_i (b_i − b̂5_i) k_i,   err3 = Σ_i b_i k_i − (bhh1 k1 + bhh2 k9 + bhh3 k12),
//!   err  = |h| · E5 / sqrt(n (E5 + 0.01 E3)),   E_p = Σ_j (err_p,j / sk_j)²   (E5 = ‖·‖² sums)
//! ```
//! which behaves like an 8th-order error estimate (controller exponent `α = 1/8 − 0.2β`,
//! defaults safety 0.9, fac_min 0.333, fac_max 6, β = 0). Continuous extension of order 7 from
//! three extra stages (14–16), computed only for steps where dense output is needed.
//! Stiffness indicator `h‖k13 − k12‖/‖y1 − ŷ12‖ > 6.1`. Not symplectic.
//!
//! P. J. Prince, J. R. Dormand, *High order embedded Runge–Kutta formulae*, J. Comput. Appl.
//! Math. 7 (1981) 67–75; Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.10 (dop853.f).
//! Statistics reproduce dop853.f (Van der Pol ε = 1e-3, tol 1e-9, h0 = 1e-6: 1348 accepted,
//! 121 rejected).

use crate::controller::Controller;
use crate::events::DenseOutput;
use crate::explicit::{combine, stage_input, ExplicitRk, SMALL};
use crate::problem::OdeSystem;
use crate::solution::Stats;
use crate::tableau::Tableau;
use crate::Method;

/// One-line description for `--method help`.
pub const DOC: &str = "Dormand-Prince 8(5,3), adaptive explicit RK of order 8 with 7th-order \
dense output; Hairer's dop853.f. Best for tight tolerances on smooth problems. Prince & Dormand 1981.";

const B: [f64; 12] = [
    5.42937341165687622380535766363e-2,
    0.0,
    0.0,
    0.0,
    0.0,
    4.45031289275240888144113950566e0,
    1.89151789931450038304281599044e0,
    -5.8012039600105847814672114227e0,
    3.1116436695781989440891606237e-1,
    -1.52160949662516078556178806805e-1,
    2.01365400804030348374776537501e-1,
    4.47106157277725905176885569043e-2,
];

/// `b − b̂5` (dop853.f ER1, ER6, …, ER12).
const ER: [f64; 12] = [
    0.1312004499419488073250102996e-01,
    0.0,
    0.0,
    0.0,
    0.0,
    -0.1225156446376204440720569753e+01,
    -0.4957589496572501915214079952e+00,
    0.1664377182454986536961530415e+01,
    -0.3503288487499736816886487290e+00,
    0.3341791187130174790297318841e+00,
    0.8192320648511571246570742613e-01,
    -0.2235530786388629525884427845e-01,
];

/// Third-order weights on stages 1, 9 and 12 (dop853.f BHH1–3).
pub const BHH: [f64; 3] = [
    0.244094488188976377952755905512e+00,
    0.733846688281611857341361741547e+00,
    0.220588235294117647058823529412e-01,
];

const fn b_hat() -> [f64; 12] {
    let mut r = [0.0; 12];
    let mut i = 0;
    while i < 12 {
        r[i] = B[i] - ER[i];
        i += 1;
    }
    r
}

/// The DOP853 tableau (12 stages; `b_hat` is the embedded 5th-order solution).
pub const TABLEAU: Tableau<12> = Tableau {
    a: [
        [0.0; 12],
        [
            5.26001519587677318785587544488e-2,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            1.97250569845378994544595329183e-2,
            5.91751709536136983633785987549e-2,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            2.95875854768068491816892993775e-2,
            0.0,
            8.87627564304205475450678981324e-2,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            2.41365134159266685502369798665e-1,
            0.0,
            -8.84549479328286085344864962717e-1,
            9.24834003261792003115737966543e-1,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            3.7037037037037037037037037037e-2,
            0.0,
            0.0,
            1.70828608729473871279604482173e-1,
            1.25467687566822425016691814123e-1,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            3.7109375e-2,
            0.0,
            0.0,
            1.70252211019544039314978060272e-1,
            6.02165389804559606850219397283e-2,
            -1.7578125e-2,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            3.70920001185047927108779319836e-2,
            0.0,
            0.0,
            1.70383925712239993810214054705e-1,
            1.07262030446373284651809199168e-1,
            -1.53194377486244017527936158236e-2,
            8.27378916381402288758473766002e-3,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            6.24110958716075717114429577812e-1,
            0.0,
            0.0,
            -3.36089262944694129406857109825e0,
            -8.68219346841726006818189891453e-1,
            2.75920996994467083049415600797e1,
            2.01540675504778934086186788979e1,
            -4.34898841810699588477366255144e1,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            4.77662536438264365890433908527e-1,
            0.0,
            0.0,
            -2.48811461997166764192642586468e0,
            -5.90290826836842996371446475743e-1,
            2.12300514481811942347288949897e1,
            1.52792336328824235832596922938e1,
            -3.32882109689848629194453265587e1,
            -2.03312017085086261358222928593e-2,
            0.0,
            0.0,
            0.0,
        ],
        [
            -9.3714243008598732571704021658e-1,
            0.0,
            0.0,
            5.18637242884406370830023853209e0,
            1.09143734899672957818500254654e0,
            -8.14978701074692612513997267357e0,
            -1.85200656599969598641566180701e1,
            2.27394870993505042818970056734e1,
            2.49360555267965238987089396762e0,
            -3.0467644718982195003823669022e0,
            0.0,
            0.0,
        ],
        [
            2.27331014751653820792359768449e0,
            0.0,
            0.0,
            -1.05344954667372501984066689879e1,
            -2.00087205822486249909675718444e0,
            -1.79589318631187989172765950534e1,
            2.79488845294199600508499808837e1,
            -2.85899827713502369474065508674e0,
            -8.87285693353062954433549289258e0,
            1.23605671757943030647266201528e1,
            6.43392746015763530355970484046e-1,
            0.0,
        ],
    ],
    b: B,
    b_hat: Some(b_hat()),
    c: [
        0.0,
        0.526001519587677318785587544488e-01,
        0.789002279381515978178381316732e-01,
        0.118350341907227396726757197510e+00,
        0.281649658092772603273242802490e+00,
        0.333333333333333333333333333333e+00,
        0.25e+00,
        0.307692307692307692307692307692e+00,
        0.651282051282051282051282051282e+00,
        0.6e+00,
        0.857142857142857142857142857142e+00,
        1.0,
    ],
    order: 8,
    embedded_order: 5,
    fsal: false,
};

/// Nodes of the three dense-output stages 14, 15, 16.
const C_DENSE: [f64; 3] = [0.1, 0.2, 0.777777777777777777777777777778];

/// Rows of the dense-output stages 14–16 over stages 1–15 (stage 13 is `f(t+h, y1)`).
const A_DENSE: [[f64; 15]; 3] = [
    [
        5.61675022830479523392909219681e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        2.53500210216624811088794765333e-1,
        -2.46239037470802489917441475441e-1,
        -1.24191423263816360469010140626e-1,
        1.5329179827876569731206322685e-1,
        8.20105229563468988491666602057e-3,
        7.56789766054569976138603589584e-3,
        -8.298e-3,
        0.0,
        0.0,
    ],
    [
        3.18346481635021405060768473261e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        2.83009096723667755288322961402e-2,
        5.35419883074385676223797384372e-2,
        -5.49237485713909884646569340306e-2,
        0.0,
        0.0,
        -1.08347328697249322858509316994e-4,
        3.82571090835658412954920192323e-4,
        -3.40465008687404560802977114492e-4,
        1.41312443674632500278074618366e-1,
        0.0,
    ],
    [
        -4.28896301583791923408573538692e-1,
        0.0,
        0.0,
        0.0,
        0.0,
        -4.69762141536116384314449447206e0,
        7.68342119606259904184240953878e0,
        4.06898981839711007970213554331e0,
        3.56727187455281109270669543021e-1,
        0.0,
        0.0,
        0.0,
        -1.39902416515901462129418009734e-3,
        2.9475147891527723389556272149e0,
        -9.15095847217987001081870187138e0,
    ],
];

/// Number of nonzero entries of `row`.
const fn nonzero_count(row: &[f64]) -> usize {
    let (mut c, mut m) = (0, 0);
    while m < row.len() {
        if row[m] != 0.0 {
            c += 1;
        }
        m += 1;
    }
    c
}

/// The nonzero entries of `row` in order: their indices and values (`M` of them).
const fn nonzero<const M: usize>(row: &[f64]) -> ([usize; M], [f64; M]) {
    let (mut idx, mut val) = ([0; M], [0.0; M]);
    let (mut q, mut m) = (0, 0);
    while m < row.len() {
        if row[m] != 0.0 {
            idx[q] = m;
            val[q] = row[m];
            q += 1;
        }
        m += 1;
    }
    assert!(q == M);
    (idx, val)
}

/// Nonzero entries per row of [`A_DENSE`] (8 in each).
const DENSE_NZ: usize = nonzero_count(&A_DENSE[0]);

/// [`A_DENSE`] by its nonzero entries.
const A_DENSE_NZ: [([usize; DENSE_NZ], [f64; DENSE_NZ]); 3] = [
    nonzero(&A_DENSE[0]),
    nonzero(&A_DENSE[1]),
    nonzero(&A_DENSE[2]),
];

/// Nonzero entries per row of [`D`] (12 in each).
const D_ROW_NZ: usize = nonzero_count(&D[0]);

/// [`D`] by its nonzero entries.
const D_NZ: [([usize; D_ROW_NZ], [f64; D_ROW_NZ]); 4] = [
    nonzero(&D[0]),
    nonzero(&D[1]),
    nonzero(&D[2]),
    nonzero(&D[3]),
];

/// Dense-output coefficients (dop853.f D4*, D5*, D6*, D7*) over stages 1–16.
const D: [[f64; 16]; 4] = [
    [
        -0.84289382761090128651353491142e+01,
        0.0,
        0.0,
        0.0,
        0.0,
        0.56671495351937776962531783590e+00,
        -0.30689499459498916912797304727e+01,
        0.23846676565120698287728149680e+01,
        0.21170345824450282767155149946e+01,
        -0.87139158377797299206789907490e+00,
        0.22404374302607882758541771650e+01,
        0.63157877876946881815570249290e+00,
        -0.88990336451333310820698117400e-01,
        0.18148505520854727256656404962e+02,
        -0.91946323924783554000451984436e+01,
        -0.44360363875948939664310572000e+01,
    ],
    [
        0.10427508642579134603413151009e+02,
        0.0,
        0.0,
        0.0,
        0.0,
        0.24228349177525818288430175319e+03,
        0.16520045171727028198505394887e+03,
        -0.37454675472269020279518312152e+03,
        -0.22113666853125306036270938578e+02,
        0.77334326684722638389603898808e+01,
        -0.30674084731089398182061213626e+02,
        -0.93321305264302278729567221706e+01,
        0.15697238121770843886131091075e+02,
        -0.31139403219565177677282850411e+02,
        -0.93529243588444783865713862664e+01,
        0.35816841486394083752465898540e+02,
    ],
    [
        0.19985053242002433820987653617e+02,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.38703730874935176555105901742e+03,
        -0.18917813819516756882830838328e+03,
        0.52780815920542364900561016686e+03,
        -0.11573902539959630126141871134e+02,
        0.68812326946963000169666922661e+01,
        -0.10006050966910838403183860980e+01,
        0.77771377980534432092869265740e+00,
        -0.27782057523535084065932004339e+01,
        -0.60196695231264120758267380846e+02,
        0.84320405506677161018159903784e+02,
        0.11992291136182789328035130030e+02,
    ],
    [
        -0.25693933462703749003312586129e+02,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.15418974869023643374053993627e+03,
        -0.23152937917604549567536039109e+03,
        0.35763911791061412378285349910e+03,
        0.93405324183624310003907691704e+02,
        -0.37458323136451633156875139351e+02,
        0.10409964950896230045147246184e+03,
        0.29840293426660503123344363579e+02,
        -0.43533456590011143754432175058e+02,
        0.96324553959188282948394950600e+02,
        -0.39177261675615439165231486172e+02,
        -0.14972683625798562581422125276e+03,
    ],
];

/// Workspace: 16 stages (stage-major), the last stage input, dense coefficients.
pub(crate) struct Dop853 {
    n: usize,
    k: Vec<f64>,
    y1: Vec<f64>,
    cont: Vec<f64>,
    t_old: f64,
    h: f64,
}

impl DenseOutput for Dop853 {
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.t_old) / self.h;
        let (c, n) = (&self.cont, self.n);
        match n {
            2 => eval_cont::<2>(c, n, s, out),
            4 => eval_cont::<4>(c, n, s, out),
            6 => eval_cont::<6>(c, n, s, out),
            _ => eval_cont::<0>(c, n, s, out),
        }
    }
    fn record(&self, t_from: f64, t_to: f64, into: &mut crate::dense::DenseSolution) {
        use crate::dense::Interpolant;
        into.push(
            t_from,
            t_to,
            Interpolant::Dop853,
            self.t_old,
            self.h,
            &[&self.cont[..8 * self.n]],
        );
    }
}

/// DOP853's 7th-order continuous extension (dop853.f `CONTD8`) at `s = (t − t_old)/h` from its
/// coefficients `c` (`8n`); `N > 0` fixes the dimension at compile time.
#[inline(always)]
pub(crate) fn eval_cont<const N: usize>(c: &[f64], n: usize, s: f64, out: &mut [f64]) {
    let n = if N > 0 { N } else { n };
    let s1 = 1.0 - s;
    for i in 0..n {
        let conpar = c[4 * n + i] + s * (c[5 * n + i] + s1 * (c[6 * n + i] + s * c[7 * n + i]));
        out[i] = c[i] + s * (c[n + i] + s1 * (c[2 * n + i] + s * (c[3 * n + i] + s1 * conpar)));
    }
}

impl Dop853 {
    /// One step; `N > 0` fixes the dimension at compile time (`N = 0`: use `self.n`).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn attempt_n<S: OdeSystem + ?Sized, const N: usize>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &mut [f64],
        atol: &[f64],
        rtol: &[f64],
        stats: &mut Stats,
    ) -> f64 {
        let n = if N > 0 { N } else { self.n };
        let a = &TABLEAU.a;
        let c = &TABLEAU.c;
        let (y, y_new, atol, rtol) = (&y[..n], &mut y_new[..n], &atol[..n], &rtol[..n]);
        let ys = &mut self.y1[..n];
        let (k1, r) = self.k.split_at_mut(n);
        let (k2, r) = r.split_at_mut(n);
        let (k3, r) = r.split_at_mut(n);
        let (k4, r) = r.split_at_mut(n);
        let (k5, r) = r.split_at_mut(n);
        let (k6, r) = r.split_at_mut(n);
        let (k7, r) = r.split_at_mut(n);
        let (k8, r) = r.split_at_mut(n);
        let (k9, r) = r.split_at_mut(n);
        let (k10, r) = r.split_at_mut(n);
        let (k11, r) = r.split_at_mut(n);
        let k12 = &mut r[..n];
        let ha21 = h * a[1][0];
        for i in 0..n {
            ys[i] = y[i] + ha21 * k1[i];
        }
        sys.rhs(t + c[1] * h, ys, k2);
        for i in 0..n {
            ys[i] = y[i] + h * (a[2][0] * k1[i] + a[2][1] * k2[i]);
        }
        sys.rhs(t + c[2] * h, ys, k3);
        for i in 0..n {
            ys[i] = y[i] + h * (a[3][0] * k1[i] + a[3][2] * k3[i]);
        }
        sys.rhs(t + c[3] * h, ys, k4);
        for i in 0..n {
            ys[i] = y[i] + h * (a[4][0] * k1[i] + a[4][2] * k3[i] + a[4][3] * k4[i]);
        }
        sys.rhs(t + c[4] * h, ys, k5);
        for i in 0..n {
            ys[i] = y[i] + h * (a[5][0] * k1[i] + a[5][3] * k4[i] + a[5][4] * k5[i]);
        }
        sys.rhs(t + c[5] * h, ys, k6);
        for i in 0..n {
            ys[i] =
                y[i] + h * (a[6][0] * k1[i] + a[6][3] * k4[i] + a[6][4] * k5[i] + a[6][5] * k6[i]);
        }
        sys.rhs(t + c[6] * h, ys, k7);
        for i in 0..n {
            ys[i] = y[i]
                + h * (a[7][0] * k1[i]
                    + a[7][3] * k4[i]
                    + a[7][4] * k5[i]
                    + a[7][5] * k6[i]
                    + a[7][6] * k7[i]);
        }
        sys.rhs(t + c[7] * h, ys, k8);
        for i in 0..n {
            ys[i] = y[i]
                + h * (a[8][0] * k1[i]
                    + a[8][3] * k4[i]
                    + a[8][4] * k5[i]
                    + a[8][5] * k6[i]
                    + a[8][6] * k7[i]
                    + a[8][7] * k8[i]);
        }
        sys.rhs(t + c[8] * h, ys, k9);
        for i in 0..n {
            ys[i] = y[i]
                + h * (a[9][0] * k1[i]
                    + a[9][3] * k4[i]
                    + a[9][4] * k5[i]
                    + a[9][5] * k6[i]
                    + a[9][6] * k7[i]
                    + a[9][7] * k8[i]
                    + a[9][8] * k9[i]);
        }
        sys.rhs(t + c[9] * h, ys, k10);
        for i in 0..n {
            ys[i] = y[i]
                + h * (a[10][0] * k1[i]
                    + a[10][3] * k4[i]
                    + a[10][4] * k5[i]
                    + a[10][5] * k6[i]
                    + a[10][6] * k7[i]
                    + a[10][7] * k8[i]
                    + a[10][8] * k9[i]
                    + a[10][9] * k10[i]);
        }
        sys.rhs(t + c[10] * h, ys, k11);
        for i in 0..n {
            ys[i] = y[i]
                + h * (a[11][0] * k1[i]
                    + a[11][3] * k4[i]
                    + a[11][4] * k5[i]
                    + a[11][5] * k6[i]
                    + a[11][6] * k7[i]
                    + a[11][7] * k8[i]
                    + a[11][8] * k9[i]
                    + a[11][9] * k10[i]
                    + a[11][10] * k11[i]);
        }
        sys.rhs(t + h, ys, k12);
        stats.fevals += 11;
        let (mut err, mut err2) = (0.0, 0.0);
        for i in 0..n {
            let b = B[0] * k1[i]
                + B[5] * k6[i]
                + B[6] * k7[i]
                + B[7] * k8[i]
                + B[8] * k9[i]
                + B[9] * k10[i]
                + B[10] * k11[i]
                + B[11] * k12[i];
            y_new[i] = y[i] + h * b;
            let sk = atol[i] + rtol[i] * y[i].abs().max(y_new[i].abs());
            let e3 = b - BHH[0] * k1[i] - BHH[1] * k9[i] - BHH[2] * k12[i];
            err2 += (e3 / sk) * (e3 / sk);
            let e5 = ER[0] * k1[i]
                + ER[5] * k6[i]
                + ER[6] * k7[i]
                + ER[7] * k8[i]
                + ER[8] * k9[i]
                + ER[9] * k10[i]
                + ER[10] * k11[i]
                + ER[11] * k12[i];
            err += (e5 / sk) * (e5 / sk);
        }
        let mut deno = err + 0.01 * err2;
        if deno <= 0.0 {
            deno = 1.0;
        }
        h.abs() * err * (1.0 / (n as f64 * deno)).sqrt()
    }
}

impl ExplicitRk for Dop853 {
    const METHOD: Method = Method::Dop853;
    const ORDER: i32 = 8;
    const STIFF_THRESHOLD: f64 = 6.1;

    fn default_controller() -> Controller {
        Controller::dop853()
    }

    fn alpha(c: &Controller) -> f64 {
        1.0 / 8.0 - c.beta * 0.2
    }

    fn new(n: usize) -> Self {
        Dop853 {
            n,
            k: vec![0.0; 16 * n],
            y1: vec![0.0; n],
            cont: vec![0.0; 8 * n],
            t_old: 0.0,
            h: 1.0,
        }
    }

    fn f_start(&mut self) -> &mut [f64] {
        &mut self.k[..self.n]
    }

    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &mut [f64],
        atol: &[f64],
        rtol: &[f64],
        stats: &mut Stats,
    ) -> f64 {
        crate::explicit::dispatch_dim!(
            self,
            S,
            [1, 2, 3, 4, 6, 8],
            (sys, t, y, h, y_new, atol, rtol, stats)
        )
    }

    fn on_accept<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t_new: f64,
        y_new: &[f64],
        stats: &mut Stats,
    ) {
        let n = self.n;
        sys.rhs(t_new, y_new, &mut self.k[12 * n..13 * n]);
        stats.fevals += 1;
    }

    fn stiffness(&self, h: f64, y_new: &[f64]) -> f64 {
        let n = self.n;
        crate::explicit::stiffness_ratio(
            h,
            &self.k[12 * n..13 * n],
            &self.k[11 * n..12 * n],
            &y_new[..n],
            &self.y1[..n],
        )
    }

    fn prepare_dense<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &[f64],
        stats: &mut Stats,
    ) {
        // As `attempt`: the same arithmetic, with loops of compile-time length for the usual
        // small dimensions (with output at many points this runs at nearly every step).
        #[cfg(target_arch = "x86_64")]
        if self.n >= crate::explicit::AVX_FROM && std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the processor has AVX (checked just above).
            return unsafe { self.prepare_dense_avx(sys, t, y, h, y_new, stats) };
        }
        match self.n {
            1 => self.prepare_dense_n::<S, 1>(sys, t, y, h, y_new, stats),
            2 => self.prepare_dense_n::<S, 2>(sys, t, y, h, y_new, stats),
            3 => self.prepare_dense_n::<S, 3>(sys, t, y, h, y_new, stats),
            4 => self.prepare_dense_n::<S, 4>(sys, t, y, h, y_new, stats),
            6 => self.prepare_dense_n::<S, 6>(sys, t, y, h, y_new, stats),
            8 => self.prepare_dense_n::<S, 8>(sys, t, y, h, y_new, stats),
            _ => self.prepare_dense_n::<S, 0>(sys, t, y, h, y_new, stats),
        }
    }

    fn advance(&mut self) {
        let n = self.n;
        self.k.copy_within(12 * n..13 * n, 0);
    }
}

impl Dop853 {
    crate::explicit::avx_attempt!();

    /// [`ExplicitRk::prepare_dense`] of any dimension, compiled for AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn prepare_dense_avx<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &[f64],
        stats: &mut Stats,
    ) {
        self.prepare_dense_n::<S, 0>(sys, t, y, h, y_new, stats)
    }

    /// The dense output of the accepted step; `N > 0` fixes the dimension at compile time
    /// (`N = 0`: use `self.n`).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn prepare_dense_n<S: OdeSystem + ?Sized, const N: usize>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &[f64],
        stats: &mut Stats,
    ) {
        let n = if N > 0 { N } else { self.n };
        self.t_old = t;
        self.h = h;
        let mut ys = std::mem::take(&mut self.y1);
        for (j, row) in A_DENSE.iter().enumerate() {
            let s = 13 + j;
            if N > 0 && N < SMALL {
                // `stage_input`'s small-dimension arithmetic over the nonzero entries only,
                // without testing each entry for zero at run time.
                let (idx, a) = &A_DENSE_NZ[j];
                let k = &self.k[..16 * n];
                for i in 0..n {
                    let mut acc = 0.0;
                    for q in 0..DENSE_NZ {
                        acc += a[q] * k[idx[q] * n + i];
                    }
                    ys[i] = y[i] + h * acc;
                }
            } else {
                stage_input(y, &self.k, n, &row[..s], h, &mut ys);
            }
            let (_, rest) = self.k.split_at_mut(s * n);
            sys.rhs(t + C_DENSE[j] * h, &ys, &mut rest[..n]);
        }
        self.y1 = ys;
        stats.fevals += 3;
        for (r, d) in D.iter().enumerate() {
            let (_, row) = self.cont.split_at_mut((4 + r) * n);
            if N > 0 {
                // `combine` over the nonzero entries only (the same sums, in the same order).
                let (idx, w) = &D_NZ[r];
                let k = &self.k[..16 * n];
                for (i, o) in row[..n].iter_mut().enumerate() {
                    let mut acc = w[0] * k[idx[0] * n + i];
                    for q in 1..D_ROW_NZ {
                        acc += w[q] * k[idx[q] * n + i];
                    }
                    *o = acc;
                }
            } else {
                combine(&self.k, n, d, &mut row[..n]);
            }
        }
        let k = &self.k;
        for i in 0..n {
            let ydiff = y_new[i] - y[i];
            let bspl = h * k[i] - ydiff;
            self.cont[i] = y[i];
            self.cont[n + i] = ydiff;
            self.cont[2 * n + i] = bspl;
            self.cont[3 * n + i] = ydiff - h * k[12 * n + i] - bspl;
            for r in 4..8 {
                self.cont[r * n + i] *= h;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tableau::order_residual;

    #[test]
    fn tableau_row_sums_and_order_conditions() {
        assert!(TABLEAU.row_sum_residual() < 1e-14);
        let a = TABLEAU.a_rows();
        let r8 = order_residual(&a, &TABLEAU.b, 8);
        assert!(r8 < 1e-12, "order 8 residual {r8}");
        assert!(
            order_residual(&a, &TABLEAU.b, 9) > 1e-8,
            "order is exactly 8"
        );
        let r5 = order_residual(&a, &TABLEAU.b_hat.unwrap(), 5);
        assert!(r5 < 1e-12, "embedded order 5 residual {r5}");
        // third-order weights on stages 1, 9, 12
        let mut b3 = [0.0; 12];
        b3[0] = BHH[0];
        b3[8] = BHH[1];
        b3[11] = BHH[2];
        assert!(order_residual(&a, &b3, 3) < 1e-14);
    }

    #[test]
    fn dense_stage_rows_sum_to_nodes() {
        for (j, row) in A_DENSE.iter().enumerate() {
            let s: f64 = row.iter().sum();
            assert!((s - C_DENSE[j]).abs() < 1e-14, "stage {}: {s}", 14 + j);
            // Stage 14 + j reads only the stages before it.
            assert!(row[13 + j..].iter().all(|&a| a == 0.0));
        }
    }

    /// The nonzero-entry tables are the rows, entry for entry.
    #[test]
    fn nonzero_tables_match_the_rows() {
        fn expand<const M: usize>(nz: &([usize; M], [f64; M]), len: usize) -> Vec<f64> {
            let mut row = vec![0.0; len];
            for q in 0..M {
                assert!(nz.1[q] != 0.0);
                row[nz.0[q]] = nz.1[q];
            }
            row
        }
        for (row, nz) in A_DENSE.iter().zip(&A_DENSE_NZ) {
            assert_eq!(expand(nz, row.len()), row.to_vec());
        }
        for (row, nz) in D.iter().zip(&D_NZ) {
            assert_eq!(expand(nz, row.len()), row.to_vec());
        }
    }

    /// The dense output prepared with the dimension fixed at compile time gives the same bits
    /// as with the dimension known at run time (`N = 0`: `stage_input`, `combine`), and so
    /// does the interpolation.
    #[test]
    fn dense_output_is_the_same_for_compile_time_dimensions() {
        struct Forced;
        impl OdeSystem for Forced {
            fn dim(&self) -> usize {
                4
            }
            fn rhs(&self, t: f64, y: &[f64], d: &mut [f64]) {
                d[0] = y[2];
                d[1] = y[3];
                d[2] = (0.2 * libm::sin(9.0 * t) - 4.0 * y[0] + 2.0 * y[1]) * 100.0;
                d[3] = (2.0 * y[0] - 2.0 * y[1]) * 100.0;
            }
        }
        let n = 4;
        let (y, h, t) = ([0.1, 0.3, -0.7, 0.25], 0.037, 1.3);
        let (mut a, mut b) = (Dop853::new(n), Dop853::new(n));
        // Stages 1-13 as an attempt leaves them (varied values, some negative).
        for (m, x) in a.k[..13 * n].iter_mut().enumerate() {
            *x = libm::sin((m as f64 + 1.0) * 0.731) * 10f64.powi(m as i32 % 5 - 2);
        }
        b.k.copy_from_slice(&a.k);
        let y_new = [0.1003, 0.2991, -0.69, 0.2512];
        let mut stats = Stats::default();
        a.prepare_dense_n::<_, 4>(&Forced, t, &y, h, &y_new, &mut stats);
        b.prepare_dense_n::<_, 0>(&Forced, t, &y, h, &y_new, &mut stats);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.k), bits(&b.k));
        assert_eq!(bits(&a.cont), bits(&b.cont));
        assert!(a.cont.iter().all(|x| x.is_finite()) && a.cont[4 * n..].iter().any(|&x| x != 0.0));
        let (mut oa, mut ob) = ([0.0; 4], [0.0; 4]);
        for s in [0.0, 0.3, 0.77, 1.0] {
            eval_cont::<4>(&a.cont, 4, s, &mut oa);
            eval_cont::<0>(&b.cont, 4, s, &mut ob);
            assert_eq!(bits(&oa), bits(&ob));
        }
    }

    /// Steps of a 120-component system take the AVX code where the processor has it
    /// (`attempt`, `prepare_dense` from `AVX_FROM` components): the same bits as the same
    /// code compiled for the baseline processor (`attempt_n`, `prepare_dense_n` called here),
    /// the stages and the dense output too.
    #[test]
    fn avx_steps_give_the_baseline_bits() {
        use crate::explicit::avx_check::{same_bits, Chain};
        let (mut a, mut b, y_new) = same_bits::<Dop853>(|m, t, y, h, y_new, atol, rtol, stats| {
            m.attempt_n::<_, 0>(&Chain, t, y, h, y_new, atol, rtol, stats)
        });
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.k), bits(&b.k));
        let y: Vec<f64> = (0..120).map(|i| libm::sin(i as f64 * 0.37) * 0.3).collect();
        let mut stats = Stats::default();
        a.prepare_dense(&Chain, 0.2, &y, 0.013, &y_new, &mut stats);
        b.prepare_dense_n::<_, 0>(&Chain, 0.2, &y, 0.013, &y_new, &mut stats);
        assert_eq!(bits(&a.cont), bits(&b.cont));
        assert!(a.cont.iter().any(|&x| x != 0.0));
    }
}
