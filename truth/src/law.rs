//! Constitutive laws of the truth belt, written as continuum laws (moment
//! against curvature κ, 1/m, and curvature rate κ̇, 1/(m·s)), so that the
//! number of nodes of the discretisation does not enter them.
//!
//! Sign: κ > 0 bends the belt the way it wraps round a wheel (the sides of
//! a loop), κ < 0 back-bends it.

/// Logistic function.
fn sigmoid(x: f64) -> f64 {
    if x >= 0.0 {
        1.0 / (1.0 + (-x).exp())
    } else {
        let e = x.exp();
        e / (1.0 + e)
    }
}

/// ln(1 + eˣ) without overflow.
fn softplus(x: f64) -> f64 {
    x.max(0.0) + (-x.abs()).exp().ln_1p()
}

/// The smooth, asymmetric, nonlinear elastic bending law.
///
/// Its tangent stiffness is
/// `B(κ) = EIs + (EI0 − EIs)·sech²(κ/κt) + EIh·σ((κ − κh)/wh) + (EIb − EIs)·σ((−κ − κb)/wb)`
/// (σ the logistic function): stiff near straight (EI0), softening to EIs
/// in the middle wrap range, hardening by EIh beyond κh (the belt's
/// tightest bend) and stiffer (EIb) when back-bent. The moment is its
/// integral from zero, in closed form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendingLaw {
    /// Soft middle-range stiffness, N·m².
    pub ei_soft: f64,
    /// Stiffness near the straight belt, N·m².
    pub ei_zero: f64,
    /// Curvature over which the near-straight stiffness gives way, 1/m.
    pub kappa_t: f64,
    /// Extra stiffness of a tight wrap, N·m².
    pub ei_hard: f64,
    /// Wrap curvature where the hardening sets in, 1/m.
    pub kappa_h: f64,
    /// Width of that transition, 1/m.
    pub w_h: f64,
    /// Back-bending stiffness, N·m².
    pub ei_back: f64,
    /// Back-bending curvature where it sets in, 1/m.
    pub kappa_b: f64,
    /// Width of that transition, 1/m.
    pub w_b: f64,
}

impl BendingLaw {
    /// The law tuned so that the Shredder belt (2450 × 160 × 8 mm, 6.4 kg)
    /// meets the means of Table 1 (see the crate docs for the figures).
    pub fn shredder() -> Self {
        BendingLaw {
            ei_soft: 0.426,
            ei_zero: 0.455,
            kappa_t: 1.8,
            ei_hard: 6.2,
            kappa_h: 9.42,
            w_h: 1.0,
            ei_back: 5.78,
            kappa_b: 0.8,
            w_b: 0.3,
        }
    }

    /// Bending damping (N·m²·s) tuned with [`BendingLaw::shredder`].
    pub const SHREDDER_DAMPING: f64 = 0.0315;

    /// Bending moment, N·m, at curvature `k`, 1/m (positive for a wrap).
    pub fn moment(&self, k: f64) -> f64 {
        let a = self.ei_soft * k;
        let b = (self.ei_zero - self.ei_soft) * self.kappa_t * (k / self.kappa_t).tanh();
        let c = self.ei_hard
            * self.w_h
            * (softplus((k - self.kappa_h) / self.w_h) - softplus(-self.kappa_h / self.w_h));
        let d = -(self.ei_back - self.ei_soft)
            * self.w_b
            * (softplus((-k - self.kappa_b) / self.w_b) - softplus(-self.kappa_b / self.w_b));
        a + b + c + d
    }

    /// Tangent stiffness dM/dκ, N·m².
    pub fn tangent(&self, k: f64) -> f64 {
        let s = 1.0 / (k / self.kappa_t).cosh();
        self.ei_soft
            + (self.ei_zero - self.ei_soft) * s * s
            + self.ei_hard * sigmoid((k - self.kappa_h) / self.w_h)
            + (self.ei_back - self.ei_soft) * sigmoid((-k - self.kappa_b) / self.w_b)
    }

    /// Stored energy per unit length, J/m, at curvature `k` (Simpson's rule
    /// over the moment, 64 panels: the law is smooth).
    pub fn energy_density(&self, k: f64) -> f64 {
        let n = 64;
        let h = k / n as f64;
        let mut s = self.moment(0.0) + self.moment(k);
        for i in 1..n {
            let w = if i % 2 == 1 { 4.0 } else { 2.0 };
            s += w * self.moment(i as f64 * h);
        }
        s * h / 3.0
    }

    /// Largest tangent stiffness over the curvatures a belt meets
    /// (|κ| ≤ 3·κh), N·m²: bounds the explicit step.
    pub fn max_tangent(&self) -> f64 {
        let span = 3.0 * self.kappa_h;
        (0..=240)
            .map(|i| self.tangent(-span + 2.0 * span * i as f64 / 240.0))
            .fold(0.0, f64::max)
    }

    /// This law with every stiffness times `ei` and every curvature times
    /// `kappa`.
    pub fn scaled(&self, ei: f64, kappa: f64) -> Self {
        BendingLaw {
            ei_soft: self.ei_soft * ei,
            ei_zero: self.ei_zero * ei,
            kappa_t: self.kappa_t * kappa,
            ei_hard: self.ei_hard * ei,
            kappa_h: self.kappa_h * kappa,
            w_h: self.w_h * kappa,
            ei_back: self.ei_back * ei,
            kappa_b: self.kappa_b * kappa,
            w_b: self.w_b * kappa,
        }
    }
}

/// The dissipative part of the bending moment against the curvature rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DampingLaw {
    /// Kelvin–Voigt: `M = c·κ̇`.
    Linear {
        /// N·m²·s.
        c: f64,
    },
    /// A power law replacing the linear one: `M = c·r0^(1−α)·κ̇·(κ̇² + ε²)^((α−1)/2)`,
    /// equal to the linear law `c·κ̇` at `κ̇ = r0`.
    Power {
        /// The matching linear coefficient, N·m²·s.
        c: f64,
        /// Exponent, 0 < α < 1.
        alpha: f64,
        /// Rate where it matches the linear law, 1/(m·s).
        rate_ref: f64,
        /// Regularisation rate, 1/(m·s).
        eps: f64,
    },
    /// Linear plus a drag `cq·|κ̇|^p·sgn κ̇`, its rate capped at `cap`.
    Drag {
        /// Linear coefficient, N·m²·s.
        c: f64,
        /// Drag coefficient, N·m·(m·s)^p.
        cq: f64,
        /// Exponent, about 2.
        p: f64,
        /// Rate above which the drag grows linearly, 1/(m·s).
        cap: f64,
    },
}

impl DampingLaw {
    /// Damping moment, N·m, at curvature rate `r`, times `scale` (a
    /// temperature factor).
    pub fn moment(&self, r: f64) -> f64 {
        match *self {
            DampingLaw::Linear { c } => c * r,
            DampingLaw::Power {
                c,
                alpha,
                rate_ref,
                eps,
            } => c * rate_ref.powf(1.0 - alpha) * r * (r * r + eps * eps).powf(0.5 * (alpha - 1.0)),
            DampingLaw::Drag { c, cq, p, cap } => {
                let a = r.abs();
                let drag = if a <= cap {
                    cq * a.powf(p)
                } else {
                    cq * cap.powf(p) + cq * p * cap.powf(p - 1.0) * (a - cap)
                };
                c * r + drag * r.signum()
            }
        }
    }

    /// Largest slope dM/dκ̇, N·m²·s: bounds the explicit step.
    pub fn max_slope(&self) -> f64 {
        match *self {
            DampingLaw::Linear { c } => c,
            DampingLaw::Power {
                c,
                alpha,
                rate_ref,
                eps,
            } => c * (rate_ref / eps).powf(1.0 - alpha),
            DampingLaw::Drag { c, cq, p, cap } => c + cq * p * cap.powf(p - 1.0),
        }
    }

    /// The linear coefficient this law is built on, N·m²·s.
    pub fn linear_level(&self) -> f64 {
        match *self {
            DampingLaw::Linear { c } | DampingLaw::Power { c, .. } | DampingLaw::Drag { c, .. } => {
                c
            }
        }
    }
}

/// Dry friction in bending, a moment (N·m) at every point of the belt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrictionLaw {
    /// None.
    None,
    /// Dahl's model: the friction moment z follows
    /// `dz/dκ = (1 − z·sgn(κ̇)/Mc)/κs` (exactly integrated per step).
    Dahl {
        /// Sliding moment, N·m.
        m_c: f64,
        /// Pre-sliding curvature, 1/m.
        kappa_s: f64,
    },
    /// Coulomb, regularised: `M = Mc·tanh(κ̇/r)`.
    Tanh {
        /// Sliding moment, N·m.
        m_c: f64,
        /// Regularising rate, 1/(m·s).
        rate: f64,
    },
}

/// Amplitude-dependent stiffness with memory (Payne-type), as a standard
/// linear solid whose arm depends on the amplitude: the elastic law holds
/// a slowly moving mean curvature κ̄ (it relaxes towards κ over
/// `tau_mean_s`), and the part of the moment about it is scaled by a
/// factor `h ≥ 1` of a low-passed strain amplitude `a` (the recent
/// |κ − κ̄|, not the instantaneous one): `h = 1 + depth·e^(−a/ac)` for
/// `depth > 0` (Payne softening: stiffer at small amplitude),
/// `h = 1 + |depth|·(1 − e^(−a/ac))` for `depth < 0` (hardening). `h`
/// never falls below 1, so the arm only ever takes energy out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Payne {
    /// Excess of the dynamic stiffness at small (`> 0`) or large (`< 0`)
    /// amplitude.
    pub depth: f64,
    /// Amplitude scale, 1/m.
    pub amp_c: f64,
    /// Memory time of the amplitude, s.
    pub tau_mem_s: f64,
    /// Time constant of the mean curvature, s.
    pub tau_mean_s: f64,
}

impl Payne {
    /// Stiffness factor about the mean at remembered amplitude `a`.
    pub fn factor(&self, a: f64) -> f64 {
        let e = (-a.abs() / self.amp_c).exp();
        if self.depth > 0.0 {
            1.0 + self.depth * e
        } else {
            1.0 - self.depth * (1.0 - e)
        }
    }
}

/// Temperature dependence: stiffness times `exp(−β·ΔT)`, damping (and
/// friction) times a WLF-like shift `10^(−C1·ΔT/(C2 + ΔT))`, ΔT from the
/// reference temperature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thermal {
    /// Stiffness coefficient, 1/K.
    pub beta_per_k: f64,
    /// WLF C1 (decades).
    pub c1: f64,
    /// WLF C2, K.
    pub c2_k: f64,
}

impl Thermal {
    /// (stiffness factor, damping factor) at `dt_k` above the reference.
    pub fn factors(&self, dt_k: f64) -> (f64, f64) {
        let d = dt_k.max(0.0);
        (
            (-self.beta_per_k * d).exp(),
            10f64.powf(-self.c1 * d / (self.c2_k + d)),
        )
    }
}

/// Everything that makes up the belt's bending behaviour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Elastic law.
    pub elastic: BendingLaw,
    /// Damping law.
    pub damping: DampingLaw,
    /// Dry friction.
    pub friction: FrictionLaw,
    /// Amplitude dependence, if any.
    pub payne: Option<Payne>,
    /// Temperature dependence, if any.
    pub thermal: Option<Thermal>,
}
