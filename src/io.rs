//! Output that is never presented as complete when it is not: every file is written under a
//! temporary name and renamed into place, and an output directory carries an `INCOMPLETE` marker
//! until the job that fills it finishes.
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

/// Errors of the output layer, naming the file involved.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("cannot write {path}: {source}")]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot create output directory {path}: {source}")]
    CreateDir {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// Writes `bytes` to `path` atomically (temporary sibling, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let err = |source| OutputError::Write {
        path: path.to_path_buf(),
        source,
    };
    if let Some(parent) = path.parent() {
        if !parent.as_os_str().is_empty() {
            fs::create_dir_all(parent).map_err(err)?;
        }
    }
    let file_name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = path.with_file_name(format!(".{file_name}.tmp{}", std::process::id()));
    fs::write(&tmp, bytes).map_err(err)?;
    fs::rename(&tmp, path).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        err(e)
    })
}

/// Name of the marker file present in an output directory while its job is unfinished.
pub const INCOMPLETE_MARKER: &str = "INCOMPLETE";

/// An output directory: created with an `INCOMPLETE` marker that only [`OutDir::finish`] removes,
/// so an interrupted or failed job never leaves a directory that looks complete.
#[derive(Debug)]
pub struct OutDir {
    path: PathBuf,
}

impl OutDir {
    /// Creates (or reuses) `path` and marks it incomplete.
    pub fn create(path: &Path) -> Result<Self, OutputError> {
        fs::create_dir_all(path).map_err(|source| OutputError::CreateDir {
            path: path.to_path_buf(),
            source,
        })?;
        let dir = Self {
            path: path.to_path_buf(),
        };
        dir.mark_incomplete("job started, not finished")?;
        Ok(dir)
    }

    /// The directory path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Path of a file inside the directory.
    pub fn file(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }

    /// Writes one file of the directory atomically.
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<PathBuf, OutputError> {
        let p = self.file(name);
        write_atomic(&p, bytes)?;
        Ok(p)
    }

    /// Rewrites the marker with a reason (e.g. the numerical failure that stopped the job).
    pub fn mark_incomplete(&self, reason: &str) -> Result<(), OutputError> {
        write_atomic(
            &self.file(INCOMPLETE_MARKER),
            format!("{reason}\n").as_bytes(),
        )
    }

    /// Removes the marker: the directory now holds a complete result.
    pub fn finish(self) -> Result<(), OutputError> {
        match fs::remove_file(self.file(INCOMPLETE_MARKER)) {
            Ok(()) => Ok(()),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
            Err(source) => Err(OutputError::Write {
                path: self.file(INCOMPLETE_MARKER),
                source,
            }),
        }
    }
}

/// Formats a table of numbers as CSV. Values use Rust's shortest round-trip representation,
/// so every printed digit is significant and reading the file back gives the same `f64` bits.
pub fn csv_string(header: &[&str], rows: impl IntoIterator<Item = impl AsRef<[f64]>>) -> String {
    let mut s = header.join(",");
    s.push('\n');
    for row in rows {
        let row = row.as_ref();
        debug_assert_eq!(row.len(), header.len(), "CSV row width");
        for (i, v) in row.iter().enumerate() {
            if i > 0 {
                s.push(',');
            }
            let _ = write!(s, "{v}");
        }
        s.push('\n');
    }
    s
}

/// Column-major variant of [`csv_string`]: one slice per column, all of the same length.
pub fn csv_from_columns(header: &[&str], columns: &[&[f64]]) -> String {
    assert_eq!(header.len(), columns.len(), "one header per column");
    let n = columns.first().map_or(0, |c| c.len());
    assert!(
        columns.iter().all(|c| c.len() == n),
        "columns of equal length"
    );
    let mut row = vec![0.0; columns.len()];
    let rows = (0..n).map(|i| {
        for (r, c) in row.iter_mut().zip(columns) {
            *r = c[i];
        }
        row.clone()
    });
    csv_string(header, rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_and_marker_lifecycle() {
        let dir = std::env::temp_dir().join(format!("rotorsim-io-test-{}", std::process::id()));
        let out = OutDir::create(&dir).unwrap();
        assert!(dir.join(INCOMPLETE_MARKER).exists());
        out.write("a.csv", b"x\n1\n").unwrap();
        assert_eq!(fs::read_to_string(dir.join("a.csv")).unwrap(), "x\n1\n");
        // No temporary file is left behind.
        let names: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert!(names.iter().all(|n| !n.contains(".tmp")), "{names:?}");
        out.finish().unwrap();
        assert!(!dir.join(INCOMPLETE_MARKER).exists());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn csv_values_round_trip_bit_for_bit() {
        let vals = [0.1 + 0.2, -1.0e-300, 6.02214076e23, std::f64::consts::PI];
        let s = csv_string(&["v_m"], vals.iter().map(|v| [*v]));
        let back: Vec<f64> = s.lines().skip(1).map(|l| l.parse().unwrap()).collect();
        for (a, b) in vals.iter().zip(&back) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
    }

    #[test]
    fn csv_from_columns_matches_rows() {
        let s = csv_from_columns(&["a", "b"], &[&[1.0, 2.0], &[3.0, 4.5]]);
        assert_eq!(s, "a,b\n1,3\n2,4.5\n");
    }
}
