//! Units: the value of the gravitational constant `G` that goes with a choice of length, time
//! and mass units.

/// A choice of units, fixing `G`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub enum Units {
    /// Hénon (N-body) units, `G = 1` (the default; also the figure-eight's units).
    #[default]
    GEqualsOne,
    /// Astronomical unit, year (Julian, 365.25 d), solar mass: `G = 4π²` (Kepler's third law
    /// with a 1-year period at 1 AU for a massless planet).
    AuYearSolarMass,
    /// Astronomical unit, day, solar mass: `G = k²` with Gauss's constant
    /// `k = 0.01720209895` (the units of mercury6 and REBOUND's outer Solar System example).
    AuDaySolarMass,
    /// Metre, second, kilogram: `G = 6.67430e-11` (CODATA 2018).
    Si,
    /// Any other units: the value of `G` in them.
    Custom(f64),
}

/// Gauss's gravitational constant `k` (AU^{3/2} day^{-1} M_sun^{-1/2}).
pub const GAUSS_K: f64 = 0.01720209895;

impl Units {
    /// The gravitational constant in these units.
    pub fn g(self) -> f64 {
        match self {
            Units::GEqualsOne => 1.0,
            Units::AuYearSolarMass => 4.0 * std::f64::consts::PI * std::f64::consts::PI,
            Units::AuDaySolarMass => GAUSS_K * GAUSS_K,
            Units::Si => 6.674_30e-11,
            Units::Custom(g) => g,
        }
    }
}
