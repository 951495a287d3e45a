//! DOP853: the explicit embedded Runge–Kutta method of order 8 of Dormand & Prince (Prince & Dormand,
//! J. Comp. Appl. Math. 7, 1981, 67–75), with the 5th/3rd-order combined error estimator, step-size
//! control, initial step and 7th-order dense output of Hairer's `dop853.f` (Hairer, Nørsett & Wanner,
//! *Solving ODEs I*, 2nd ed., §II.5 "DOP853" and §II.6, p. 194). The coefficients below are those of
//! `dop853.f` (module `coeffs`), given to 30 digits there and rounded to f64 here.
//!
//! The dense output needs three extra stages; they are computed lazily, in
//! [`Stepper::prepare_interpolation`], only for steps in which a sample or an event is wanted, so
//! stepping without samples costs 12 evaluations per step.

// The coefficients are transcribed with all the digits `dop853.f` gives, so they can be checked against
// the source digit by digit; the compiler rounds them to the nearest f64.
#![allow(clippy::excessive_precision, clippy::unreadable_literal)]

use super::control::{combine, cubic_dense_output, AdaptiveSteps, Controller};
use super::{all_finite, Method, OdeSystem, StepError, Stepper, StepperState};

/// Nodes c₁..c₁₆ (`c2..c16` of `dop853.f`; c₁₃ = 1 is the FSAL stage f(t + h, y₁)).
const C: [f64; 16] = [
    0.0,
    0.526_001_519_587_677_318_785_587_544_488e-1,
    0.789_002_279_381_515_978_178_381_316_732e-1,
    0.118_350_341_907_227_396_726_757_197_510,
    0.281_649_658_092_772_603_273_242_802_490,
    0.333_333_333_333_333_333_333_333_333_333,
    0.25,
    0.307_692_307_692_307_692_307_692_307_692,
    0.651_282_051_282_051_282_051_282_051_282,
    0.6,
    0.857_142_857_142_857_142_857_142_857_142,
    1.0,
    1.0,
    0.1,
    0.2,
    0.777_777_777_777_777_777_777_777_777_778,
];

/// Rows of the Runge–Kutta matrix as (stage index, aᵢⱼ), stages numbered from 0 (`a21..a1615` of
/// `dop853.f`). Row 12 is the 8th-order solution b (`b1, b6..b12`); rows 13–15 are the extra stages
/// of the dense output, which use the FSAL stage 12 = f(t + h, y₁).
const A: [&[(usize, f64)]; 16] = [
    &[],
    &[(0, 5.26001519587677318785587544488e-2)],
    &[
        (0, 1.97250569845378994544595329183e-2),
        (1, 5.91751709536136983633785987549e-2),
    ],
    &[
        (0, 2.95875854768068491816892993775e-2),
        (2, 8.87627564304205475450678981324e-2),
    ],
    &[
        (0, 2.41365134159266685502369798665e-1),
        (2, -8.84549479328286085344864962717e-1),
        (3, 9.24834003261792003115737966543e-1),
    ],
    &[
        (0, 3.7037037037037037037037037037e-2),
        (3, 1.70828608729473871279604482173e-1),
        (4, 1.25467687566822425016691814123e-1),
    ],
    &[
        (0, 3.7109375e-2),
        (3, 1.70252211019544039314978060272e-1),
        (4, 6.02165389804559606850219397283e-2),
        (5, -1.7578125e-2),
    ],
    &[
        (0, 3.70920001185047927108779319836e-2),
        (3, 1.70383925712239993810214054705e-1),
        (4, 1.07262030446373284651809199168e-1),
        (5, -1.53194377486244017527936158236e-2),
        (6, 8.27378916381402288758473766002e-3),
    ],
    &[
        (0, 6.24110958716075717114429577812e-1),
        (3, -3.36089262944694129406857109825),
        (4, -8.68219346841726006818189891453e-1),
        (5, 2.75920996994467083049415600797e1),
        (6, 2.01540675504778934086186788979e1),
        (7, -4.34898841810699588477366255144e1),
    ],
    &[
        (0, 4.77662536438264365890433908527e-1),
        (3, -2.48811461997166764192642586468),
        (4, -5.90290826836842996371446475743e-1),
        (5, 2.12300514481811942347288949897e1),
        (6, 1.52792336328824235832596922938e1),
        (7, -3.32882109689848629194453265587e1),
        (8, -2.03312017085086261358222928593e-2),
    ],
    &[
        (0, -9.3714243008598732571704021658e-1),
        (3, 5.18637242884406370830023853209),
        (4, 1.09143734899672957818500254654),
        (5, -8.14978701074692612513997267357),
        (6, -1.85200656599969598641566180701e1),
        (7, 2.27394870993505042818970056734e1),
        (8, 2.49360555267965238987089396762),
        (9, -3.0467644718982195003823669022),
    ],
    &[
        (0, 2.27331014751653820792359768449),
        (3, -1.05344954667372501984066689879e1),
        (4, -2.00087205822486249909675718444),
        (5, -1.79589318631187989172765950534e1),
        (6, 2.79488845294199600508499808837e1),
        (7, -2.85899827713502369474065508674),
        (8, -8.87285693353062954433549289258),
        (9, 1.23605671757943030647266201528e1),
        (10, 6.43392746015763530355970484046e-1),
    ],
    &[
        (0, 5.42937341165687622380535766363e-2),
        (5, 4.45031289275240888144113950566),
        (6, 1.89151789931450038304281599044),
        (7, -5.8012039600105847814672114227),
        (8, 3.1116436695781989440891606237e-1),
        (9, -1.52160949662516078556178806805e-1),
        (10, 2.01365400804030348374776537501e-1),
        (11, 4.47106157277725905176885569043e-2),
    ],
    &[
        (0, 5.61675022830479523392909219681e-2),
        (6, 2.53500210216624811088794765333e-1),
        (7, -2.46239037470802489917441475441e-1),
        (8, -1.24191423263816360469010140626e-1),
        (9, 1.5329179827876569731206322685e-1),
        (10, 8.20105229563468988491666602057e-3),
        (11, 7.56789766054569976138603589584e-3),
        (12, -8.298e-3),
    ],
    &[
        (0, 3.18346481635021405060768473261e-2),
        (5, 2.83009096723667755288322961402e-2),
        (6, 5.35419883074385676223797384372e-2),
        (7, -5.49237485713909884646569340306e-2),
        (10, -1.08347328697249322858509316994e-4),
        (11, 3.82571090835658412954920192323e-4),
        (12, -3.40465008687404560802977114492e-4),
        (13, 1.41312443674632500278074618366e-1),
    ],
    &[
        (0, -4.28896301583791923408573538692e-1),
        (5, -4.69762141536116384314449447206),
        (6, 7.68342119606259904184240953878),
        (7, 4.06898981839711007970213554331),
        (8, 3.56727187455281109270669543021e-1),
        (12, -1.39902416515901462129418009734e-3),
        (13, 2.9475147891527723389556272149),
        (14, -9.15095847217987001081870187138),
    ],
];

/// The 3rd-order embedded weights `bhh1, bhh2, bhh3` (on stages 0, 8, 11), subtracted from b.
const BHH: [(usize, f64); 3] = [
    (0, 0.244094488188976377952755905512),
    (8, 0.733846688281611857341361741547),
    (11, 0.220588235294117647058823529412e-1),
];

/// The 5th-order error estimator `er1, er6..er12` of `dop853.f`.
const ER: [(usize, f64); 8] = [
    (0, 0.1312004499419488073250102996e-1),
    (5, -0.1225156446376204440720569753e1),
    (6, -0.4957589496572501915214079952),
    (7, 0.1664377182454986536961530415e1),
    (8, -0.3503288487499736816886487290),
    (9, 0.3341791187130174790297318841),
    (10, 0.8192320648511571246570742613e-1),
    (11, -0.2235530786388629525884427845e-1),
];

/// Dense output coefficients `d41..d416`, `d51..`, `d61..`, `d71..` of `dop853.f` (rows 4–7 of the
/// continuous extension), over stages 0, 5..15.
const DENSE: [[(usize, f64); 12]; 4] = [
    [
        (0, -0.84289382761090128651353491142e1),
        (5, 0.56671495351937776962531783590),
        (6, -0.30689499459498916912797304727e1),
        (7, 0.23846676565120698287728149680e1),
        (8, 0.21170345824450282767155149946e1),
        (9, -0.87139158377797299206789907490),
        (10, 0.22404374302607882758541771650e1),
        (11, 0.63157877876946881815570249290),
        (12, -0.88990336451333310820698117400e-1),
        (13, 0.18148505520854727256656404962e2),
        (14, -0.91946323924783554000451984436e1),
        (15, -0.44360363875948939664310572000e1),
    ],
    [
        (0, 0.10427508642579134603413151009e2),
        (5, 0.24228349177525818288430175319e3),
        (6, 0.16520045171727028198505394887e3),
        (7, -0.37454675472269020279518312152e3),
        (8, -0.22113666853125306036270938578e2),
        (9, 0.77334326684722638389603898808e1),
        (10, -0.30674084731089398182061213626e2),
        (11, -0.93321305264302278729567221706e1),
        (12, 0.15697238121770843886131091075e2),
        (13, -0.31139403219565177677282850411e2),
        (14, -0.93529243588444783865713862664e1),
        (15, 0.35816841486394083752465898540e2),
    ],
    [
        (0, 0.19985053242002433820987653617e2),
        (5, -0.38703730874935176555105901742e3),
        (6, -0.18917813819516756882830838328e3),
        (7, 0.52780815920542364900561016686e3),
        (8, -0.11573902539959630126141871134e2),
        (9, 0.68812326946963000169666922661e1),
        (10, -0.10006050966910838403183860980e1),
        (11, 0.77771377980534432092869265740),
        (12, -0.27782057523535084065932004339e1),
        (13, -0.60196695231264120758267380846e2),
        (14, 0.84320405506677161018159903784e2),
        (15, 0.11992291136182789328035130030e2),
    ],
    [
        (0, -0.25693933462703749003312586129e2),
        (5, -0.15418974869023643374053993627e3),
        (6, -0.23152937917604549567536039109e3),
        (7, 0.35763911791061412378285349910e3),
        (8, 0.93405324183624310003907691704e2),
        (9, -0.37458323136451633156875139351e2),
        (10, 0.10409964950896230045147246184e3),
        (11, 0.29840293426660503123344363579e2),
        (12, -0.43533456590011143754432175058e2),
        (13, 0.96324553959188282948394950600e2),
        (14, -0.39177261675615439165231486172e2),
        (15, -0.14972683625798562581422125276e3),
    ],
];

/// Weight of the 3rd-order estimate in the combined error (`0.01` in `dop853.f`).
const ERR3_WEIGHT: f64 = 0.01;

/// Step controller of `dop853.f`: safety 0.9, step ratio in [0.333, 6], exponent 1/8 − 0.2β, with the
/// PI stabilisation β = 0.04 (`dop853.f` defaults to β = 0 and allows up to 0.1): on an eccentric Kepler
/// orbit it halved the rejected steps and made the error proportional to the tolerance.
const CONTROLLER: Controller = Controller {
    safety: 0.9,
    min_ratio: 0.333,
    max_ratio: 6.0,
    exponent: 1.0 / 8.0 - 0.2 * 0.04,
    beta: 0.04,
};

/// The Dormand–Prince 8(5,3) method with error control and 7th-order dense output.
#[derive(Debug, Clone)]
pub struct Dop853<const N: usize> {
    steps: AdaptiveSteps<N>,
    /// Stages of the last accepted step: 0..=11 the method's, 12 = f(t, y) (FSAL), 13..=15 dense.
    k: [[f64; N]; 16],
    /// Coefficients of the continuous extension (`rcont` of `dop853.f`), row 0 the state at the start of
    /// the last step; rows 4..8 valid only when `dense_ready`.
    dense: [[f64; N]; 8],
    dense_ready: bool,
}

impl<const N: usize> Dop853<N> {
    /// A stepper keeping the local error per step below atol + rtol·|y| (in Hairer's RMS norm).
    #[must_use]
    pub fn new(rtol: f64, atol: f64) -> Self {
        Self {
            steps: AdaptiveSteps::new(CONTROLLER, rtol, atol),
            k: [[0.0; N]; 16],
            dense: [[0.0; N]; 8],
            dense_ready: false,
        }
    }
}

impl<const N: usize> Stepper<N> for Dop853<N> {
    fn init<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t0: f64,
        y0: &[f64; N],
        t_end: f64,
    ) -> Result<(), StepError> {
        self.k = [[0.0; N]; 16];
        self.dense = [[0.0; N]; 8];
        self.dense[0] = *y0;
        self.dense_ready = true;
        let order = Method::Dop853.order();
        let started = self
            .steps
            .start(sys, (t0, y0), t_end, &mut self.k[12], order);
        self.k[0] = self.k[12];
        started
    }

    fn step<S: OdeSystem<N>>(&mut self, sys: &S, t_limit: f64) -> Result<(), StepError> {
        let mut k = [[0.0; N]; 13];
        let mut y_new = [0.0; N];
        let mut non_finite = false;
        let y = self.steps.state.y;
        loop {
            let Some((h, t_new)) = self.steps.trial(t_limit, non_finite)? else {
                return Ok(());
            };

            k[0] = self.k[12];
            let mut y_stage = [0.0; N];
            for s in 1..12 {
                combine(&y, h, A[s], &k, &mut y_stage);
                let t_stage = if s == 11 {
                    t_new
                } else {
                    self.steps.state.t + C[s] * h
                };
                sys.rhs(t_stage, &y_stage, &mut k[s]);
            }
            combine(&y, h, A[12], &k, &mut y_new);
            self.steps.state.stats.rhs_evaluations += 11;

            // Combined 5th/3rd-order error estimate (dop853.f, label 'error estimation').
            let mut err5 = 0.0;
            let mut err3 = 0.0;
            for i in 0..N {
                let sk = self.steps.weight(y[i], y_new[i]);
                let b_sum: f64 = A[12].iter().map(|&(j, b)| b * k[j][i]).sum();
                let e3 = b_sum - BHH.iter().map(|&(j, b)| b * k[j][i]).sum::<f64>();
                let e5: f64 = ER.iter().map(|&(j, e)| e * k[j][i]).sum();
                err3 += (e3 / sk).powi(2);
                err5 += (e5 / sk).powi(2);
            }
            let mut denominator = err5 + ERR3_WEIGHT * err3;
            if denominator <= 0.0 {
                denominator = 1.0;
            }
            #[allow(clippy::cast_precision_loss)]
            let err = h * err5 * (1.0 / (N as f64 * denominator)).sqrt();

            let finite = err.is_finite() && all_finite(&y_new);
            if finite && err > 1.0 {
                self.steps.reject(h, Some(err));
                continue;
            }
            if finite {
                sys.rhs(t_new, &y_new, &mut k[12]);
                self.steps.state.stats.rhs_evaluations += 1;
            }
            if !finite || !all_finite(&k[12]) {
                non_finite = true;
                self.steps.reject(h, None);
                continue;
            }

            self.steps.accept(h, err, (t_new, &y_new));
            self.k[..13].copy_from_slice(&k);
            // The cubic Hermite part of the dense output is free; the rest waits for a request.
            cubic_dense_output(h, &y, &k[0], &y_new, &k[12], &mut self.dense);
            self.dense_ready = false;
            return Ok(());
        }
    }

    fn prepare_interpolation<S: OdeSystem<N>>(&mut self, sys: &S) {
        if self.dense_ready {
            return;
        }
        let h = self.steps.h_last;
        let mut y_stage = [0.0; N];
        for s in 13..16 {
            let (done, rest) = self.k.split_at_mut(s);
            combine(&self.dense[0], h, A[s], done, &mut y_stage);
            sys.rhs(self.steps.state.t_prev + C[s] * h, &y_stage, &mut rest[0]);
        }
        self.steps.state.stats.rhs_evaluations += 3;
        // A non-finite extra stage leaves the (finite) cubic Hermite part alone rather than pass NaN on.
        let finite = self.k[13..16].iter().all(all_finite);
        for (row, coefficients) in DENSE.iter().enumerate() {
            for i in 0..N {
                let sum: f64 = coefficients.iter().map(|&(j, d)| d * self.k[j][i]).sum();
                self.dense[4 + row][i] = if finite { h * sum } else { 0.0 };
            }
        }
        self.dense_ready = true;
    }

    fn state(&self) -> &StepperState<N> {
        &self.steps.state
    }
    /// 7th-order dense output (`contd8` of `dop853.f`) once [`Stepper::prepare_interpolation`] ran for
    /// this step; the cubic Hermite interpolant (its first four terms) before that.
    fn interpolate(&self, t: f64, out: &mut [f64; N]) {
        let r = &self.dense;
        self.steps.interpolate(r, t, out, |i, s, s1| {
            if self.dense_ready {
                r[4][i] + s * (r[5][i] + s1 * (r[6][i] + s * r[7][i]))
            } else {
                0.0
            }
        });
    }
}
