//! Replay of recorded airloads onto the blade: a load provider for the rotor run.
//!
//! For any time t (or azimuth) and radius, [`AirloadReplay`] gives the airloads per unit span in
//! the deformed section frame (docs/formats.md): normal force along +z, chord force along -y (positive
//! = drag), pitching moment about +x at the quarter chord (positive nose up).
//!
//! - Azimuth: periodic linear interpolation between the recorded azimuths (exact at them,
//!   continuous across 360 deg), or, as an option, the Fourier series truncated to N harmonics
//!   (uniform azimuth grid; exact for loads containing no harmonic above N).
//! - Span: linear interpolation between stations (exact at them). Inboard of the first station the
//!   loads taper linearly to zero at the root cut-out (the start of the aerofoil); outboard of
//!   the last station they taper linearly to zero at the tip r/R = 1; zero outside. Both ends are
//!   free edges where the pressure difference, hence every airload, vanishes; the linear taper is
//!   the simplest continuous shape that keeps the recorded value at the station and carries over
//!   a short span little load (docs/flight_records.md quantifies it).
//! - Modes: one revolution, the revolution average (periodic forcing), or the recorded
//!   revolutions in sequence (the whole sequence repeats after its last revolution).
//!
//! Queries do not allocate; the provider is `Send + Sync` and can be shared through `Arc`.
use super::{FlightError, FlightRecord};

/// Start of the UH-60A aerofoil (chord.dat / airfoil.dat of the shared UH-60A data: x = 1.220 m)
/// over R = 8.178 m: the default root cut-out when the record's metadata gives none.
pub const UH60A_ROOT_CUTOUT_R_OVER_R: f64 = 1.220 / 8.178;

/// Which revolutions drive the replay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReplayMode {
    /// One recorded revolution (by its number), repeated: periodic forcing.
    Revolution(u32),
    /// The average of all recorded revolutions, repeated: periodic forcing.
    Average,
    /// The recorded revolutions one after the other (no gaps allowed), repeated as a whole.
    Sequence,
}

/// Options of the replay.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ReplayOptions {
    /// Keep only harmonics 0..=N in azimuth (periodic modes, uniform azimuth grid, N < n_az/2).
    pub harmonics: Option<usize>,
    /// Root cut-out r/R where the inboard taper reaches zero. Default: metadata key
    /// `root_cutout_r_over_R`, else [`UH60A_ROOT_CUTOUT_R_OVER_R`].
    pub root_cutout_r_over_r: Option<f64>,
}

/// Airloads per unit span at one section (section frame of docs/formats.md).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[allow(non_snake_case)]
pub struct SectionLoads {
    /// Normal force [N/m], along +z.
    pub normal_N_per_m: f64,
    /// Chord force [N/m], along -y (positive = drag, toward the trailing edge).
    pub chord_N_per_m: f64,
    /// Pitching moment about +x at the quarter chord [N m/m], positive nose up.
    pub moment_N_m_per_m: f64,
}

impl SectionLoads {
    fn from(v: [f64; 3]) -> Self {
        Self {
            normal_N_per_m: v[0],
            chord_N_per_m: v[1],
            moment_N_m_per_m: v[2],
        }
    }
}

/// The load provider (see the module doc).
#[derive(Debug, Clone)]
pub struct AirloadReplay {
    omega_deg_s: f64,
    radius_m: f64,
    /// Azimuth span of one replay period [deg]: 360, or 360 x revolutions in sequence.
    period_deg: f64,
    /// Azimuth of the record's time origin of the first replayed sample's revolution [deg].
    psi0_deg: f64,
    /// Sample azimuths within the period, strictly increasing in [0, period).
    azimuths: Vec<f64>,
    /// Step of a uniform azimuth grid [deg]: lets a query find its interval without a search.
    uniform_step: Option<f64>,
    /// Spanwise nodes r/R: the stations plus the zero-load root and tip nodes.
    nodes: Vec<f64>,
    /// Loads at (azimuth, node), index `i_az * nodes.len() + i_node`.
    values: Vec<[f64; 3]>,
    /// Harmonic truncation: N and coefficients at (node, m), m = 0 (mean), 2k-1 (cos k), 2k (sin k).
    harmonics: Option<(usize, Vec<[f64; 3]>)>,
}

impl AirloadReplay {
    /// Builds the provider; errors name the missing revolution or the unmet grid condition.
    pub fn new(
        record: &FlightRecord,
        mode: ReplayMode,
        options: ReplayOptions,
    ) -> Result<Self, FlightError> {
        let revs = record.revolutions();
        let az = record.azimuths_deg();
        let st = record.stations_r_over_r();
        let (n_az, n_st) = (az.len(), st.len());
        let root = match options.root_cutout_r_over_r {
            Some(r) => r,
            None => match record.meta.raw.get("root_cutout_r_over_R") {
                Some(v) => v.as_f64().ok_or_else(|| {
                    FlightError::Replay(format!(
                        "metadata key `root_cutout_r_over_R`: expected a number, found {v}"
                    ))
                })?,
                None => UH60A_ROOT_CUTOUT_R_OVER_R,
            },
        };
        if !(0.0..1.0).contains(&root) {
            return Err(FlightError::Replay(format!(
                "root cut-out r/R {root} is outside [0, 1)"
            )));
        }
        // Spanwise nodes: zero at the root cut-out (if inboard of the first station) and at the tip.
        let add_root = root < st[0];
        let add_tip = st[n_st - 1] < 1.0;
        let mut nodes = Vec::with_capacity(n_st + 2);
        if add_root {
            nodes.push(root);
        }
        nodes.extend_from_slice(st);
        if add_tip {
            nodes.push(1.0);
        }
        let n_nodes = nodes.len();
        let off = usize::from(add_root);
        let sample = |i_rev: usize, i_az: usize, i_st: usize| -> [f64; 3] {
            let i = record.index(i_rev, i_az, i_st);
            [
                record.normal_n_per_m()[i],
                record.chord_n_per_m()[i],
                record.moment_n_m_per_m()[i],
            ]
        };
        // Which recorded revolutions feed each replay sample.
        let (rev_indices, period_deg, psi0_deg): (Vec<usize>, f64, f64) = match mode {
            ReplayMode::Revolution(k) => {
                let i = revs.iter().position(|&r| r == k).ok_or_else(|| {
                    FlightError::Replay(format!(
                        "revolution {k} is not in the record (revolutions {})",
                        list(revs)
                    ))
                })?;
                (vec![i], 360.0, 0.0)
            }
            ReplayMode::Average => ((0..revs.len()).collect(), 360.0, 0.0),
            ReplayMode::Sequence => {
                let missing = record.missing_revolutions();
                if !missing.is_empty() {
                    return Err(FlightError::Replay(format!(
                        "sequence replay needs consecutive revolutions; missing revolution(s) {}",
                        list(&missing)
                    )));
                }
                if options.harmonics.is_some() {
                    return Err(FlightError::Replay(
                        "harmonic truncation applies to the periodic modes (one revolution, average), not to a sequence".into(),
                    ));
                }
                (
                    (0..revs.len()).collect(),
                    360.0 * revs.len() as f64,
                    360.0 * revs[0] as f64,
                )
            }
        };
        let sequence = mode == ReplayMode::Sequence;
        let n_samples = if sequence { revs.len() * n_az } else { n_az };
        let mut azimuths = Vec::with_capacity(n_samples);
        let mut values = vec![[0.0; 3]; n_samples * n_nodes];
        for s in 0..n_samples {
            let (k, i_az) = (s / n_az, s % n_az);
            azimuths.push(360.0 * k as f64 + az[i_az]);
            let row = &mut values[s * n_nodes..(s + 1) * n_nodes];
            for i_st in 0..n_st {
                row[off + i_st] = if sequence {
                    sample(rev_indices[k], i_az, i_st)
                } else {
                    let mut acc = [0.0; 3];
                    for &ir in &rev_indices {
                        let v = sample(ir, i_az, i_st);
                        for q in 0..3 {
                            acc[q] += v[q];
                        }
                    }
                    let inv = rev_indices.len() as f64;
                    // One revolution: dividing by 1 keeps the recorded value exactly.
                    acc.map(|a| a / inv)
                };
            }
        }
        let harmonics = match options.harmonics {
            None => None,
            Some(n) => Some((n, fourier(&azimuths, &values, n_nodes, n)?)),
        };
        let step = period_deg / azimuths.len() as f64;
        let uniform_step = azimuths
            .iter()
            .enumerate()
            .all(|(j, &a)| (a - (azimuths[0] + j as f64 * step)).abs() <= 1e-9 * period_deg)
            .then_some(step);
        Ok(Self {
            uniform_step,
            omega_deg_s: record.meta.rotor_speed_deg_s(),
            radius_m: record.meta.radius_m,
            period_deg,
            psi0_deg,
            azimuths,
            nodes,
            values,
            harmonics,
        })
    }

    /// Loads at time t [s] (t = psi / Omega, psi from the record's revolution 0, azimuth 0) and
    /// radius r [m] from the rotor axis.
    pub fn section_loads(&self, t: f64, r_m: f64) -> SectionLoads {
        self.at_azimuth(t * self.omega_deg_s, r_m / self.radius_m)
    }

    /// Loads a blade `ahead_deg` ahead of the reference blade sees at time t: those at its own
    /// azimuth `Omega t + ahead_deg`.
    pub fn section_loads_ahead(&self, t: f64, r_m: f64, ahead_deg: f64) -> SectionLoads {
        self.at_azimuth(t * self.omega_deg_s + ahead_deg, r_m / self.radius_m)
    }

    /// Loads at azimuth psi [deg] and r/R. psi counts from the record's time origin (revolution 0,
    /// azimuth 0): in the periodic modes only psi mod 360 matters; in sequence mode psi = 720 + 10
    /// is azimuth 10 deg of revolution 2.
    pub fn at_azimuth(&self, psi_deg: f64, r_over_r: f64) -> SectionLoads {
        let nodes = &self.nodes;
        if !(r_over_r >= nodes[0] && r_over_r <= nodes[nodes.len() - 1]) {
            return SectionLoads::default();
        }
        let j = nodes.partition_point(|&s| s <= r_over_r);
        let (lo, w) = if j >= nodes.len() {
            (nodes.len() - 1, 0.0)
        } else {
            (j - 1, (r_over_r - nodes[j - 1]) / (nodes[j] - nodes[j - 1]))
        };
        let mut psi = (psi_deg - self.psi0_deg).rem_euclid(self.period_deg);
        if psi >= self.period_deg {
            psi = 0.0; // rem_euclid of a tiny negative value rounds up to the period
        }
        let at_node = |i: usize| match &self.harmonics {
            Some((n, coef)) => series(*n, &coef[i * (2 * n + 1)..(i + 1) * (2 * n + 1)], psi),
            None => self.interp_azimuth(psi, i),
        };
        let a = at_node(lo);
        if w == 0.0 {
            return SectionLoads::from(a);
        }
        let b = at_node(lo + 1);
        SectionLoads::from([0, 1, 2].map(|q| a[q] + w * (b[q] - a[q])))
    }

    /// Periodic linear interpolation in azimuth at spanwise node `i`.
    fn interp_azimuth(&self, psi: f64, i: usize) -> [f64; 3] {
        let az = &self.azimuths;
        let n = az.len();
        let nn = self.nodes.len();
        let v = |s: usize| self.values[s * nn + i];
        if n == 1 {
            return v(0);
        }
        // j = number of samples at or before psi.
        let j = match self.uniform_step {
            Some(step) => {
                let g = ((psi - az[0]) / step).floor();
                let mut j = if g < 0.0 { 0 } else { (g as usize + 1).min(n) };
                // The guess is off by at most one where rounding bites; settle it exactly.
                while j > 0 && az[j - 1] > psi {
                    j -= 1;
                }
                while j < n && az[j] <= psi {
                    j += 1;
                }
                j
            }
            None => az.partition_point(|&a| a <= psi),
        };
        let (lo, hi, a_lo, a_hi) = if j == 0 {
            (n - 1, 0, az[n - 1] - self.period_deg, az[0])
        } else if j == n {
            (n - 1, 0, az[n - 1], az[0] + self.period_deg)
        } else {
            (j - 1, j, az[j - 1], az[j])
        };
        let (x, y) = (v(lo), v(hi));
        let w = (psi - a_lo) / (a_hi - a_lo);
        if w == 0.0 {
            return x;
        }
        [0, 1, 2].map(|q| x[q] + w * (y[q] - x[q]))
    }

    /// The spanwise nodes r/R (stations plus the zero-load root and tip nodes).
    pub fn nodes_r_over_r(&self) -> &[f64] {
        &self.nodes
    }

    /// Replay period [s]: one revolution, or the whole sequence.
    pub fn period_s(&self) -> f64 {
        self.period_deg / self.omega_deg_s
    }
}

fn list(v: &[u32]) -> String {
    v.iter()
        .map(|r| r.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Fourier coefficients of the samples on a uniform azimuth grid, harmonics 0..=n.
fn fourier(
    az: &[f64],
    values: &[[f64; 3]],
    n_nodes: usize,
    n: usize,
) -> Result<Vec<[f64; 3]>, FlightError> {
    let m = az.len();
    if 2 * n >= m {
        return Err(FlightError::Replay(format!(
            "{n} harmonics need more than {} azimuths per revolution; the record has {m}",
            2 * n
        )));
    }
    let d = 360.0 / m as f64;
    if let Some(j) = (0..m).find(|&j| (az[j] - (az[0] + j as f64 * d)).abs() > 1e-9 * 360.0) {
        return Err(FlightError::Replay(format!(
            "harmonic truncation needs a uniform azimuth grid; azimuth {} deg (index {j}) is off the grid of step {d} deg",
            az[j]
        )));
    }
    let width = 2 * n + 1;
    let mut coef = vec![[0.0; 3]; n_nodes * width];
    for (j, &psi) in az.iter().enumerate() {
        let p = psi.to_radians();
        for i in 0..n_nodes {
            let v = values[j * n_nodes + i];
            let c = &mut coef[i * width..(i + 1) * width];
            for q in 0..3 {
                c[0][q] += v[q] / m as f64;
            }
            for k in 1..=n {
                let (s, co) = (k as f64 * p).sin_cos();
                for q in 0..3 {
                    c[2 * k - 1][q] += 2.0 * v[q] * co / m as f64;
                    c[2 * k][q] += 2.0 * v[q] * s / m as f64;
                }
            }
        }
    }
    Ok(coef)
}

/// Evaluates a truncated Fourier series at psi [deg] (cos/sin of k psi by rotation recurrence).
fn series(n: usize, c: &[[f64; 3]], psi_deg: f64) -> [f64; 3] {
    let (s1, c1) = psi_deg.to_radians().sin_cos();
    let mut out = c[0];
    let (mut ck, mut sk) = (1.0, 0.0);
    for k in 1..=n {
        (ck, sk) = (ck * c1 - sk * s1, sk * c1 + ck * s1);
        for q in 0..3 {
            out[q] += c[2 * k - 1][q] * ck + c[2 * k][q] * sk;
        }
    }
    out
}
