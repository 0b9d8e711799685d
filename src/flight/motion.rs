//! The measured rigid blade motion of a flight record (optional `STEM.motion.csv`, MCAP channel
//! `/rotor/motion`): flap, lag and pitch of blade 1 per (revolution, azimuth), on the airloads'
//! azimuth grid (docs/formats.md "Flight record").
//!
//! Sign conventions: flap up positive, lag aft (against the rotation) positive, pitch nose-up
//! positive (the blade's root pitch); azimuth as for the airloads.
//! [`BladeMotion::periodic`] turns the revolution average into a truncated Fourier series
//! ([`PeriodicMotion`]) that gives angles and rates at any azimuth without allocating.
use super::FlightError;
use std::path::PathBuf;

/// Column names of `STEM.motion.csv`, in the order rotorsim writes them.
pub const MOTION_COLUMNS: [&str; 5] = [
    "revolution",
    "azimuth_deg",
    "flap_deg",
    "lag_deg",
    "pitch_deg",
];

/// The measured rigid motion of blade 1, every listed revolution on the same azimuth grid (the
/// record's airload grid when it belongs to a [`super::FlightRecord`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BladeMotion {
    revolutions: Vec<u32>,
    azimuths_deg: Vec<f64>,
    /// Flat over `i_rev * n_az + i_az`.
    flap_deg: Vec<f64>,
    lag_deg: Vec<f64>,
    pitch_deg: Vec<f64>,
}

/// Angles [rad] and rates [rad/s] of the blade motion at one azimuth.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotionSample {
    pub flap_rad: f64,
    pub lag_rad: f64,
    pub pitch_rad: f64,
    pub flap_rate_rad_s: f64,
    pub lag_rate_rad_s: f64,
    pub pitch_rate_rad_s: f64,
}

/// The revolution-averaged motion as a periodic function of azimuth: per channel (flap, lag,
/// pitch) `x(psi) = a0 + sum_{k=1..H} (a_k cos k psi + b_k sin k psi)` [rad]; rates are
/// `Omega dx/dpsi`.
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodicMotion {
    omega_rad_s: f64,
    /// a0 per channel [rad] (flap, lag, pitch).
    mean: [f64; 3],
    /// a_k per channel, index k - 1.
    cos: Vec<[f64; 3]>,
    /// b_k per channel, index k - 1.
    sin: Vec<[f64; 3]>,
}

fn invalid(msg: String) -> FlightError {
    FlightError::Invalid {
        path: PathBuf::from("<blade motion>"),
        msg,
    }
}

impl BladeMotion {
    /// Builds a motion from flat arrays over `i_rev * n_az + i_az` [deg]; checks that revolutions
    /// and azimuths increase strictly (azimuths in [0, 360)), lengths agree and values are finite.
    pub fn new(
        revolutions: Vec<u32>,
        azimuths_deg: Vec<f64>,
        flap_deg: Vec<f64>,
        lag_deg: Vec<f64>,
        pitch_deg: Vec<f64>,
    ) -> Result<Self, FlightError> {
        let n = revolutions.len() * azimuths_deg.len();
        if n == 0 {
            return Err(invalid(
                "no motion samples (need revolutions and azimuths)".into(),
            ));
        }
        if !revolutions.windows(2).all(|w| w[0] < w[1]) {
            return Err(invalid("motion revolutions must increase strictly".into()));
        }
        if !azimuths_deg.windows(2).all(|w| w[0] < w[1])
            || azimuths_deg.iter().any(|p| !(0.0..360.0).contains(p))
        {
            return Err(invalid(
                "motion azimuths must increase strictly within [0, 360)".into(),
            ));
        }
        for (name, v) in [
            ("flap", &flap_deg),
            ("lag", &lag_deg),
            ("pitch", &pitch_deg),
        ] {
            if v.len() != n {
                return Err(invalid(format!(
                    "motion {name}: {} values, expected {n}",
                    v.len()
                )));
            }
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(invalid(format!(
                    "motion {name}: non-finite value at index {i}"
                )));
            }
        }
        Ok(Self {
            revolutions,
            azimuths_deg,
            flap_deg,
            lag_deg,
            pitch_deg,
        })
    }

    /// Revolution numbers present, strictly increasing.
    pub fn revolutions(&self) -> &[u32] {
        &self.revolutions
    }
    /// Azimuth grid [deg], the same for every revolution, strictly increasing in [0, 360).
    pub fn azimuths_deg(&self) -> &[f64] {
        &self.azimuths_deg
    }
    /// Flat index of (revolution index, azimuth index).
    pub fn index(&self, i_rev: usize, i_az: usize) -> usize {
        i_rev * self.azimuths_deg.len() + i_az
    }
    /// Flap angle [deg], up positive, flat over [`Self::index`].
    pub fn flap_deg(&self) -> &[f64] {
        &self.flap_deg
    }
    /// Lag angle [deg], aft (against the rotation) positive, flat over [`Self::index`].
    pub fn lag_deg(&self) -> &[f64] {
        &self.lag_deg
    }
    /// Root pitch [deg], nose up positive, flat over [`Self::index`].
    pub fn pitch_deg(&self) -> &[f64] {
        &self.pitch_deg
    }

    /// The revolution average per azimuth [deg]: (flap, lag, pitch).
    pub fn average_deg(&self) -> [Vec<f64>; 3] {
        let n_az = self.azimuths_deg.len();
        let n_rev = self.revolutions.len() as f64;
        let avg = |v: &[f64]| -> Vec<f64> {
            (0..n_az)
                .map(|j| v.iter().skip(j).step_by(n_az).sum::<f64>() / n_rev)
                .collect()
        };
        [
            avg(&self.flap_deg),
            avg(&self.lag_deg),
            avg(&self.pitch_deg),
        ]
    }

    /// The largest harmonic [`Self::periodic`] accepts: n_az / 2 - 1 (no Nyquist term).
    pub fn max_harmonics(&self) -> usize {
        (self.azimuths_deg.len() / 2).saturating_sub(1)
    }

    /// The revolution average as a periodic function of azimuth, truncated to `harmonics`
    /// harmonics (discrete Fourier series on the uniform azimuth grid; rates = the analytic
    /// derivative of the series times `omega_rad_s`). Exact at the samples when `harmonics` is
    /// [`Self::max_harmonics`] and the data are band-limited to it. Errors if the grid is not
    /// uniform (spacing 360/n_az within 1e-9 deg), `harmonics` exceeds n_az/2 - 1, or
    /// `omega_rad_s` is not finite.
    pub fn periodic(
        &self,
        harmonics: usize,
        omega_rad_s: f64,
    ) -> Result<PeriodicMotion, FlightError> {
        let az = &self.azimuths_deg;
        let n = az.len();
        if !omega_rad_s.is_finite() {
            return Err(invalid(format!(
                "periodic motion: rotor speed {omega_rad_s} rad/s is not finite"
            )));
        }
        let step = 360.0 / n as f64;
        if let Some(w) = az.windows(2).find(|w| ((w[1] - w[0]) - step).abs() > 1e-9) {
            return Err(invalid(format!(
                "periodic motion needs a uniform azimuth grid (step 360/{n} = {step} deg); azimuths {} and {} deg are {} deg apart",
                w[0],
                w[1],
                w[1] - w[0]
            )));
        }
        if harmonics > self.max_harmonics() {
            return Err(invalid(format!(
                "periodic motion: {harmonics} harmonics asked for, but {n} azimuths per revolution resolve at most {} (n_az/2 - 1)",
                self.max_harmonics()
            )));
        }
        let avg = self.average_deg();
        let psi: Vec<f64> = az.iter().map(|p| p.to_radians()).collect();
        let mut mean = [0.0; 3];
        for (c, v) in avg.iter().enumerate() {
            mean[c] = v.iter().map(|x| x.to_radians()).sum::<f64>() / n as f64;
        }
        let mut cos = vec![[0.0; 3]; harmonics];
        let mut sin = vec![[0.0; 3]; harmonics];
        for k in 1..=harmonics {
            for (j, &p) in psi.iter().enumerate() {
                let (s, c) = (k as f64 * p).sin_cos();
                for ch in 0..3 {
                    let x = avg[ch][j].to_radians();
                    cos[k - 1][ch] += x * c;
                    sin[k - 1][ch] += x * s;
                }
            }
            for ch in 0..3 {
                cos[k - 1][ch] *= 2.0 / n as f64;
                sin[k - 1][ch] *= 2.0 / n as f64;
            }
        }
        Ok(PeriodicMotion {
            omega_rad_s,
            mean,
            cos,
            sin,
        })
    }
}

impl PeriodicMotion {
    /// Angles and rates at azimuth `psi_rad` (any real value; the series is 2 pi periodic).
    /// Does not allocate.
    pub fn at(&self, psi_rad: f64) -> MotionSample {
        let mut x = self.mean;
        let mut d = [0.0; 3];
        for (k0, (a, b)) in self.cos.iter().zip(&self.sin).enumerate() {
            let k = (k0 + 1) as f64;
            let (s, c) = (k * psi_rad).sin_cos();
            for ch in 0..3 {
                x[ch] += a[ch] * c + b[ch] * s;
                d[ch] += k * (b[ch] * c - a[ch] * s);
            }
        }
        let w = self.omega_rad_s;
        MotionSample {
            flap_rad: x[0],
            lag_rad: x[1],
            pitch_rad: x[2],
            flap_rate_rad_s: w * d[0],
            lag_rate_rad_s: w * d[1],
            pitch_rate_rad_s: w * d[2],
        }
    }

    /// Number of harmonics kept.
    pub fn harmonics(&self) -> usize {
        self.cos.len()
    }

    /// Rotor speed [rad/s] the rates are scaled with.
    pub fn omega_rad_s(&self) -> f64 {
        self.omega_rad_s
    }

    /// Mean a0 [rad] per channel (flap, lag, pitch).
    pub fn mean_rad(&self) -> [f64; 3] {
        self.mean
    }

    /// Cosine and sine coefficients (a_k, b_k) [rad] of harmonic `k` (1..=harmonics) per channel
    /// (flap, lag, pitch); `None` outside that range.
    pub fn coefficients_rad(&self, k: usize) -> Option<([f64; 3], [f64; 3])> {
        let i = k.checked_sub(1)?;
        Some((*self.cos.get(i)?, *self.sin.get(i)?))
    }

    /// Amplitude sqrt(a_k^2 + b_k^2) [rad] of harmonic `k` per channel; `None` outside 1..=harmonics.
    pub fn amplitude_rad(&self, k: usize) -> Option<[f64; 3]> {
        let (a, b) = self.coefficients_rad(k)?;
        Some([0, 1, 2].map(|c| a[c].hypot(b[c])))
    }
}

/// Where a motion row went wrong: the column and what was expected.
#[derive(Debug)]
pub(crate) struct RowError {
    pub column: &'static str,
    pub msg: String,
}

/// Builds a [`BladeMotion`] row by row in file order, checking each row against the airloads'
/// azimuth grid: revolutions increase (each revolution's rows together), azimuths increase within
/// a revolution, lie on the grid, and none is missing.
pub(crate) struct MotionAssembler<'a> {
    grid: &'a [f64],
    revolutions: Vec<u32>,
    /// Index into `grid` of the next expected azimuth of the current revolution.
    next: usize,
    last_psi: f64,
    flap: Vec<f64>,
    lag: Vec<f64>,
    pitch: Vec<f64>,
}

fn grid_text(grid: &[f64]) -> String {
    match grid {
        [] => "empty".into(),
        [a] => format!("1 azimuth: {a} deg"),
        [a, z] => format!("2 azimuths: {a}, {z} deg"),
        [a, b, .., z] => format!("{} azimuths: {a}, {b}, ..., {z} deg", grid.len()),
    }
}

impl<'a> MotionAssembler<'a> {
    pub fn new(grid: &'a [f64]) -> Self {
        Self {
            grid,
            revolutions: Vec::new(),
            next: 0,
            last_psi: f64::NEG_INFINITY,
            flap: Vec::new(),
            lag: Vec::new(),
            pitch: Vec::new(),
        }
    }

    /// True when no row has been pushed.
    pub fn is_empty(&self) -> bool {
        self.revolutions.is_empty()
    }

    fn incomplete(&self) -> Option<String> {
        let rev = *self.revolutions.last()?;
        (self.next < self.grid.len()).then(|| {
            format!(
                "revolution {rev} has {} of the {} azimuths of the airloads' grid; azimuth {} deg (and any after it) missing",
                self.next,
                self.grid.len(),
                self.grid[self.next]
            )
        })
    }

    /// One row [deg].
    pub fn push(&mut self, rev: u32, psi: f64, v: [f64; 3]) -> Result<(), RowError> {
        let err = |column, msg| Err(RowError { column, msg });
        match self.revolutions.last().copied() {
            Some(cur) if rev == cur => {
                if psi <= self.last_psi {
                    return err(
                        "azimuth_deg",
                        format!(
                            "{psi} deg does not increase within revolution {rev} (the row before has {} deg); expected the azimuths of a revolution in increasing order, each once",
                            self.last_psi
                        ),
                    );
                }
            }
            Some(cur) if rev < cur => {
                return err(
                    "revolution",
                    format!(
                        "revolution {rev} after revolution {cur}; expected revolutions in increasing order, each revolution's rows together"
                    ),
                )
            }
            _ => {
                if let Some(msg) = self.incomplete() {
                    return err(
                        "revolution",
                        format!("revolution {rev} starts, but {msg}"),
                    );
                }
                self.revolutions.push(rev);
                self.next = 0;
            }
        }
        match self.grid.get(self.next) {
            Some(&g) if g == psi => {}
            Some(&g) if self.grid.contains(&psi) => {
                return err(
                    "azimuth_deg",
                    format!(
                        "revolution {rev}: azimuth {g} deg missing (expected it before {psi} deg; the airloads' grid has {})",
                        grid_text(self.grid)
                    ),
                )
            }
            _ => {
                return err(
                    "azimuth_deg",
                    format!(
                        "{psi} deg is not on the airloads' azimuth grid ({})",
                        grid_text(self.grid)
                    ),
                )
            }
        }
        for (name, x) in ["flap_deg", "lag_deg", "pitch_deg"].into_iter().zip(v) {
            if !x.is_finite() {
                return err(name, format!("{x} is not a finite number"));
            }
        }
        self.next += 1;
        self.last_psi = psi;
        self.flap.push(v[0]);
        self.lag.push(v[1]);
        self.pitch.push(v[2]);
        Ok(())
    }

    /// The motion, or what is missing at the end of the input.
    pub fn finish(self) -> Result<BladeMotion, String> {
        if self.is_empty() {
            return Err("no motion rows".into());
        }
        if let Some(msg) = self.incomplete() {
            return Err(format!("at the end: {msg}"));
        }
        BladeMotion::new(
            self.revolutions,
            self.grid.to_vec(),
            self.flap,
            self.lag,
            self.pitch,
        )
        .map_err(|e| e.to_string())
    }
}
