//! Sectional properties: 6x6 stiffness about the beam reference line built from principal
//! stiffnesses and centroid/shear-centre offsets, and mass properties with centre-of-mass offset.
//!
//! Axes: 1 = along the beam, 2 = chordwise, 3 = normal (flapwise). `EI2` multiplies curvature
//! kappa_2 (flap bending about axis 2), `EI3` multiplies kappa_3 (lag bending about axis 3).
use std::path::Path;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum SectionError {
    #[error("section table {file}: cannot read: {source}")]
    Io {
        file: String,
        source: std::io::Error,
    },
    #[error("section table {file}, line {line}: {msg}")]
    Parse {
        file: String,
        line: usize,
        msg: String,
    },
    #[error("section table {file}: missing column `{column}` (expected the columns of blade_sections_yeo.csv: {expected})")]
    MissingColumn {
        file: String,
        column: String,
        expected: String,
    },
    #[error("section table {file}: {msg}")]
    Invalid { file: String, msg: String },
}

/// Columns of a section table (same as `../shared/data/uh60a/blade_sections_yeo.csv`).
pub const SECTION_COLUMNS: [&str; 17] = [
    "s_m",
    "EA_N",
    "EI2_Nm2",
    "EI3_Nm2",
    "GJ_Nm2",
    "GA2_N",
    "GA3_N",
    "m_kg_per_m",
    "I1_kgm",
    "I2_kgm",
    "I3_kgm",
    "cm2_m",
    "cm3_m",
    "sc2_m",
    "sc3_m",
    "ca2_m",
    "ca3_m",
];

/// One spanwise station of sectional data (SI units). `Default` is all zeros: for the offsets
/// of a section on its reference line (`..Default::default()`), never for stiffness or mass.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct SectionProps {
    #[serde(default)]
    pub s_m: f64,
    #[serde(rename = "EA_N")]
    pub ea: f64,
    #[serde(rename = "EI2_Nm2")]
    pub ei2: f64,
    #[serde(rename = "EI3_Nm2")]
    pub ei3: f64,
    #[serde(rename = "GJ_Nm2")]
    pub gj: f64,
    #[serde(rename = "GA2_N")]
    pub ga2: f64,
    #[serde(rename = "GA3_N")]
    pub ga3: f64,
    #[serde(rename = "m_kg_per_m")]
    pub m: f64,
    /// Mass moments of inertia per unit span about the centre of mass [kg m].
    #[serde(rename = "I1_kgm")]
    pub i1: f64,
    #[serde(rename = "I2_kgm")]
    pub i2: f64,
    #[serde(rename = "I3_kgm")]
    pub i3: f64,
    #[serde(rename = "cm2_m", default)]
    pub cm2: f64,
    #[serde(rename = "cm3_m", default)]
    pub cm3: f64,
    #[serde(rename = "sc2_m", default)]
    pub sc2: f64,
    #[serde(rename = "sc3_m", default)]
    pub sc3: f64,
    #[serde(rename = "ca2_m", default)]
    pub ca2: f64,
    #[serde(rename = "ca3_m", default)]
    pub ca3: f64,
}

impl SectionProps {
    /// The first value that is not physical, as (key, what was expected): stiffnesses finite
    /// and positive, mass and inertias finite and non-negative, offsets finite.
    pub fn check(&self) -> Result<(), (&'static str, &'static str)> {
        for (k, v) in [
            ("EA_N", self.ea),
            ("GA2_N", self.ga2),
            ("GA3_N", self.ga3),
            ("GJ_Nm2", self.gj),
            ("EI2_Nm2", self.ei2),
            ("EI3_Nm2", self.ei3),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err((k, "a finite positive stiffness"));
            }
        }
        for (k, v) in [
            ("m_kg_per_m", self.m),
            ("I1_kgm", self.i1),
            ("I2_kgm", self.i2),
            ("I3_kgm", self.i3),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err((k, "a finite non-negative mass or inertia"));
            }
        }
        for (k, v) in [
            ("cm2_m", self.cm2),
            ("cm3_m", self.cm3),
            ("sc2_m", self.sc2),
            ("sc3_m", self.sc3),
            ("ca2_m", self.ca2),
            ("ca3_m", self.ca3),
        ] {
            if !v.is_finite() {
                return Err((k, "a finite offset"));
            }
        }
        Ok(())
    }

    fn as_array(&self) -> [f64; 17] {
        [
            self.s_m, self.ea, self.ei2, self.ei3, self.gj, self.ga2, self.ga3, self.m, self.i1,
            self.i2, self.i3, self.cm2, self.cm3, self.sc2, self.sc3, self.ca2, self.ca3,
        ]
    }
    fn from_array(a: &[f64; 17]) -> Self {
        SectionProps {
            s_m: a[0],
            ea: a[1],
            ei2: a[2],
            ei3: a[3],
            gj: a[4],
            ga2: a[5],
            ga3: a[6],
            m: a[7],
            i1: a[8],
            i2: a[9],
            i3: a[10],
            cm2: a[11],
            cm3: a[12],
            sc2: a[13],
            sc3: a[14],
            ca2: a[15],
            ca3: a[16],
        }
    }

    /// 6x6 sectional stiffness about the reference line, ordering (Gamma_1..3, kappa_1..3).
    ///
    /// With P mapping reference strains to the strains that the principal stiffnesses act on,
    /// axial strain at the centroid `e = G1 + k2 ca3 - k3 ca2`, shear strains at the shear
    /// centre `g2 = G2 - k1 sc3`, `g3 = G3 + k1 sc2`: `C = P^T diag(EA,GA2,GA3,GJ,EI2,EI3) P`.
    pub fn stiffness(&self) -> [[f64; 6]; 6] {
        let mut p = [[0.0; 6]; 6];
        for (i, row) in p.iter_mut().enumerate() {
            row[i] = 1.0;
        }
        p[0][4] = self.ca3;
        p[0][5] = -self.ca2;
        p[1][3] = -self.sc3;
        p[2][3] = self.sc2;
        let d = [self.ea, self.ga2, self.ga3, self.gj, self.ei2, self.ei3];
        let mut cm = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                cm[i][j] = (0..6).map(|k| p[k][i] * d[k] * p[k][j]).sum();
            }
        }
        cm
    }

    /// Centre-of-mass offset in the section frame.
    pub fn cm_offset(&self) -> [f64; 3] {
        [0.0, self.cm2, self.cm3]
    }

    /// Inertia tensor per unit span about the reference point (parallel axis from the centre of
    /// mass): `J = diag(I1, I2, I3) + m (|xi|^2 I - xi xi^T)`.
    pub fn inertia_ref(&self) -> [[f64; 3]; 3] {
        let xi = self.cm_offset();
        let x2 = xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2];
        let d = [self.i1, self.i2, self.i3];
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                (if i == j { d[i] + self.m * x2 } else { 0.0 }) - self.m * xi[i] * xi[j]
            })
        })
    }

    /// 6x6 sectional mass matrix about the reference point, ordering (v, omega), material frame.
    pub fn mass_matrix(&self) -> [[f64; 6]; 6] {
        let xi = self.cm_offset();
        let j = self.inertia_ref();
        let m = self.m;
        let mut mm = [[0.0; 6]; 6];
        for i in 0..3 {
            mm[i][i] = m;
            for k in 0..3 {
                mm[3 + i][3 + k] = j[i][k];
            }
        }
        // p = m (v + omega x xi) -> block -m xi~ ; h = m xi x v + J omega -> block m xi~
        let s = [
            [0.0, -xi[2], xi[1]],
            [xi[2], 0.0, -xi[0]],
            [-xi[1], xi[0], 0.0],
        ];
        for i in 0..3 {
            for k in 0..3 {
                mm[i][3 + k] = -m * s[i][k];
                mm[3 + i][k] = m * s[i][k];
            }
        }
        mm
    }
}

/// A spanwise table of stations, linearly interpolated in s.
#[derive(Clone, Debug, PartialEq)]
pub struct SectionTable {
    pub stations: Vec<SectionProps>,
    pub source: String,
}

impl SectionTable {
    pub fn uniform(p: SectionProps) -> Self {
        SectionTable {
            stations: vec![p],
            source: "uniform".into(),
        }
    }

    pub fn new(stations: Vec<SectionProps>, source: &str) -> Result<Self, SectionError> {
        if stations.is_empty() {
            return Err(SectionError::Invalid {
                file: source.into(),
                msg: "no stations".into(),
            });
        }
        for w in stations.windows(2) {
            if w[1].s_m <= w[0].s_m {
                return Err(SectionError::Invalid {
                    file: source.into(),
                    msg: format!(
                        "s_m must increase strictly (found {} after {})",
                        w[1].s_m, w[0].s_m
                    ),
                });
            }
        }
        for (i, st) in stations.iter().enumerate() {
            let a = st.as_array();
            for (k, (&x, col)) in a.iter().zip(SECTION_COLUMNS).enumerate() {
                // EA, EI2, EI3, GJ, GA2, GA3 are stiffnesses; m, I1, I2, I3 mass properties
                let expected = match k {
                    1..=6 if !(x.is_finite() && x > 0.0) => "a positive finite stiffness",
                    7..=10 if !(x.is_finite() && x >= 0.0) => "a non-negative finite mass property",
                    _ if !x.is_finite() => "a finite value",
                    _ => continue,
                };
                return Err(SectionError::Invalid {
                    file: source.into(),
                    msg: format!(
                        "station {} (s_m = {}): {col} = {x}: expected {expected}",
                        i + 1,
                        st.s_m
                    ),
                });
            }
        }
        Ok(SectionTable {
            stations,
            source: source.into(),
        })
    }

    /// Read a CSV with the columns of [`SECTION_COLUMNS`] (any order, extra columns rejected).
    pub fn from_csv(path: &Path) -> Result<Self, SectionError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| SectionError::Io {
            file: file.clone(),
            source,
        })?;
        Self::from_csv_str(&text, &file)
    }

    pub fn from_csv_str(text: &str, file: &str) -> Result<Self, SectionError> {
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let headers = rdr
            .headers()
            .map_err(|e| SectionError::Parse {
                file: file.into(),
                line: 1,
                msg: e.to_string(),
            })?
            .clone();
        let mut idx = [0usize; 17];
        for (k, col) in SECTION_COLUMNS.iter().enumerate() {
            idx[k] = headers.iter().position(|h| h == *col).ok_or_else(|| {
                SectionError::MissingColumn {
                    file: file.into(),
                    column: col.to_string(),
                    expected: SECTION_COLUMNS.join(","),
                }
            })?;
        }
        if let Some(h) = headers.iter().find(|h| !SECTION_COLUMNS.contains(h)) {
            return Err(SectionError::Parse {
                file: file.into(),
                line: 1,
                msg: format!("unknown column `{h}`"),
            });
        }
        let mut stations = Vec::new();
        for rec in rdr.records() {
            let rec = rec.map_err(|e| SectionError::Parse {
                file: file.into(),
                line: e.position().map(|p| p.line() as usize).unwrap_or(0),
                msg: e.to_string(),
            })?;
            let line = rec.position().map(|p| p.line() as usize).unwrap_or(0);
            let mut a = [0.0; 17];
            for k in 0..17 {
                let f = rec.get(idx[k]).unwrap_or("");
                a[k] = f.parse::<f64>().map_err(|_| SectionError::Parse {
                    file: file.into(),
                    line,
                    msg: format!("column `{}`: `{f}` is not a number", SECTION_COLUMNS[k]),
                })?;
            }
            stations.push(SectionProps::from_array(&a));
        }
        Self::new(stations, file)
    }

    /// Properties at arc length `s` (linear interpolation, constant extrapolation).
    pub fn at(&self, s: f64) -> SectionProps {
        let st = &self.stations;
        if st.len() == 1 || s <= st[0].s_m {
            return st[0];
        }
        if s >= st[st.len() - 1].s_m {
            return st[st.len() - 1];
        }
        let k = st.partition_point(|p| p.s_m <= s) - 1;
        let (a, b) = (st[k].as_array(), st[k + 1].as_array());
        let w = (s - st[k].s_m) / (st[k + 1].s_m - st[k].s_m);
        let mut r = [0.0; 17];
        for i in 0..17 {
            r[i] = a[i] + w * (b[i] - a[i]);
        }
        r[0] = s;
        SectionProps::from_array(&r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    fn base() -> SectionProps {
        SectionProps {
            s_m: 0.0,
            ea: 1e7,
            ei2: 2e4,
            ei3: 5e4,
            gj: 1e4,
            ga2: 3e6,
            ga3: 4e6,
            m: 10.0,
            i1: 0.5,
            i2: 0.1,
            i3: 0.4,
            ..Default::default()
        }
    }

    #[test]
    fn centroid_offset_gives_analytic_extension_bending_coupling() {
        // Axial force at the reference line from a pure lag curvature k3 with the tension centre
        // at chordwise offset a: N = -EA a k3, M3 = (EI3 + EA a^2) k3.
        let mut p = base();
        p.ca2 = 0.05;
        p.ca3 = -0.02;
        let cm = p.stiffness();
        assert!((cm[0][5] - (-p.ea * 0.05)).abs() < 1e-6);
        assert!((cm[0][4] - (p.ea * -0.02)).abs() < 1e-6);
        assert!((cm[5][5] - (p.ei3 + p.ea * 0.05 * 0.05)).abs() < 1e-6);
        assert!((cm[4][4] - (p.ei2 + p.ea * 0.02 * 0.02)).abs() < 1e-6);
        assert!((cm[4][5] - (-p.ea * -0.02 * 0.05)).abs() < 1e-6);
        for i in 0..6 {
            for j in 0..6 {
                assert!((cm[i][j] - cm[j][i]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn shear_centre_offset_gives_analytic_shear_torsion_coupling() {
        let mut p = base();
        p.sc2 = 0.03;
        p.sc3 = 0.01;
        let cm = p.stiffness();
        assert!((cm[1][3] - (-p.ga2 * 0.01)).abs() < 1e-9);
        assert!((cm[2][3] - (p.ga3 * 0.03)).abs() < 1e-9);
        assert!((cm[3][3] - (p.gj + p.ga2 * 1e-4 + p.ga3 * 9e-4)).abs() < 1e-6);
    }

    #[test]
    fn cm_offset_mass_matrix_matches_rigid_body_formula() {
        let mut p = base();
        p.cm2 = 0.04;
        let mm = p.mass_matrix();
        // kinetic energy of a translation v = e3 with omega = e1: section point moves with
        // v + omega x xi = e3 + e1 x (0.04 e2) = (1 + 0.04) e3.
        let u = [0.0, 0.0, 1.0, 1.0, 0.0, 0.0];
        let mut e = 0.0;
        for i in 0..6 {
            for j in 0..6 {
                e += 0.5 * u[i] * mm[i][j] * u[j];
            }
        }
        let expect = 0.5 * p.m * 1.04_f64.powi(2) + 0.5 * p.i1;
        assert!((e - expect).abs() < 1e-12, "{e} vs {expect}");
    }

    #[test]
    fn reads_the_uh60a_table_and_interpolates() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("rotors/data/blade_sections_yeo.csv");
        let t = SectionTable::from_csv(&path).expect("table");
        assert_eq!(t.stations.len(), 46);
        let a = t.stations[1];
        let b = t.stations[2];
        let mid = t.at(0.5 * (a.s_m + b.s_m));
        assert!((mid.i2 - 0.5 * (a.i2 + b.i2)).abs() < 1e-12);
        let err = SectionTable::from_csv_str("s_m,EA_N\n0,1\n", "x.csv").unwrap_err();
        assert!(
            err.to_string().contains("missing column `EI2_Nm2`"),
            "{err}"
        );
    }
}
