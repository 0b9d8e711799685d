//! Output that is never presented as complete when it is not, and never mixed with an earlier
//! run's. Every file is written under a temporary name and renamed into place. A result folder is
//! filled in a staging sibling (`.<name>.staging-<run_id>`), carries an `INCOMPLETE` marker until
//! its job finishes, and is published by renaming it to its final path together with a
//! `manifest.json` (run id, times, version, git commit, command line, inputs and outputs with
//! their sha256). An earlier folder at that path is moved aside first and removed once the new
//! one is in place. A sibling lock file (`.<name>.lock`, holding the pid) refuses a second run
//! into the same folder while one is running. docs/run.md, "Result folders".
use sha2::{Digest, Sha256};
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{SystemTime, UNIX_EPOCH};

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
    #[error("cannot read input {path}: {source}")]
    ReadInput {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("output folder {path} is in use by another rotorsim run ({holder}, lock file {lock}); wait for it to end or choose another --out")]
    Locked {
        path: PathBuf,
        holder: String,
        lock: PathBuf,
    },
    #[error("output folder {path}: lock file {lock} exists but holds no pid; remove it if no rotorsim run is writing to {path}")]
    BadLock { path: PathBuf, lock: PathBuf },
    #[error("output folder {path}: {msg}")]
    Invalid { path: PathBuf, msg: String },
    #[error("cannot publish {path} (its files are left in {staging}, removed by the next run into it): {source}")]
    Publish {
        path: PathBuf,
        staging: PathBuf,
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
    if let Err(e) = fs::write(&tmp, bytes) {
        // a full disk leaves a partial temporary file: not ours to leave behind
        let _ = fs::remove_file(&tmp);
        return Err(err(e));
    }
    fs::rename(&tmp, path).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        err(e)
    })
}

/// Name of the marker file present in an output directory while its job is unfinished.
pub const INCOMPLETE_MARKER: &str = "INCOMPLETE";

/// Name of the manifest of every result folder.
pub const MANIFEST: &str = "manifest.json";

/// Short git commit the binary was built from (build.rs), "unknown" when built without git.
pub const GIT_COMMIT: &str = env!("ROTORSIM_GIT_COMMIT");

/// Seconds and milliseconds since the Unix epoch (times before it read as the epoch).
fn unix_parts(t: SystemTime) -> (u64, u32) {
    let d = t.duration_since(UNIX_EPOCH).unwrap_or_default();
    (d.as_secs(), d.subsec_millis())
}

/// Civil date (year, month, day) of a day count since 1970-01-01 (proleptic Gregorian).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = if z >= 0 { z } else { z - 146_096 } / 146_097;
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

/// (year, month, day, hour, minute, second, millisecond) in UTC.
fn utc_fields(t: SystemTime) -> (i64, u32, u32, u64, u64, u64, u32) {
    let (s, ms) = unix_parts(t);
    let (y, mo, d) = civil_from_days((s / 86_400) as i64);
    let sod = s % 86_400;
    (y, mo, d, sod / 3600, sod / 60 % 60, sod % 60, ms)
}

/// A UTC time as RFC 3339 with milliseconds, e.g. `2024-02-29T13:05:09.042Z`.
pub fn rfc3339(t: SystemTime) -> String {
    let (y, mo, d, h, mi, s, ms) = utc_fields(t);
    format!("{y:04}-{mo:02}-{d:02}T{h:02}:{mi:02}:{s:02}.{ms:03}Z")
}

static RUN_COUNTER: AtomicUsize = AtomicUsize::new(0);

/// A run id unique on the machine: UTC start time, process id and a per-process counter.
fn new_run_id(t: SystemTime) -> String {
    let (y, mo, d, h, mi, s, ms) = utc_fields(t);
    let n = RUN_COUNTER.fetch_add(1, Ordering::Relaxed);
    format!(
        "{y:04}{mo:02}{d:02}T{h:02}{mi:02}{s:02}.{ms:03}Z-{}-{n}",
        std::process::id()
    )
}

/// Fingerprint of what defines a run's model: the sha256 of the `files`' sha256s (contents, not
/// paths, in order) and of the `extra` lines (e.g. `--set` values). Equal fingerprints mean the
/// same deck, record and overrides wherever the files lie.
pub fn inputs_fingerprint(files: &[PathBuf], extra: &[String]) -> std::io::Result<String> {
    let mut h = Sha256::new();
    for f in files {
        let (sha, _) = sha256_file(f)
            .map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", f.display())))?;
        h.update(sha.as_bytes());
        h.update(b"\n");
    }
    for e in extra {
        h.update(e.as_bytes());
        h.update(b"\n");
    }
    Ok(hex(&h.finalize()))
}

/// Lower-case hex of a digest.
fn hex(bytes: &[u8]) -> String {
    let mut s = String::with_capacity(2 * bytes.len());
    for b in bytes {
        let _ = write!(s, "{b:02x}");
    }
    s
}

/// sha256 (lower-case hex) and size of a file.
pub fn sha256_file(path: &Path) -> std::io::Result<(String, u64)> {
    use std::io::Read;
    let mut f = fs::File::open(path)?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    let mut size = 0u64;
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            break;
        }
        size += n as u64;
        h.update(&buf[..n]);
    }
    Ok((hex(&h.finalize()), size))
}

/// Files under `dir` (recursively, symbolic links not followed), as (relative path with `/`
/// separators, path), sorted.
fn walk_files(dir: &Path) -> std::io::Result<Vec<(String, PathBuf)>> {
    fn go(root: &Path, dir: &Path, out: &mut Vec<(String, PathBuf)>) -> std::io::Result<()> {
        for e in fs::read_dir(dir)? {
            let e = e?;
            let p = e.path();
            let ft = e.file_type()?;
            if ft.is_dir() {
                go(root, &p, out)?;
            } else {
                let rel = p
                    .strip_prefix(root)
                    .unwrap_or(&p)
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect::<Vec<_>>()
                    .join("/");
                out.push((rel, p));
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    go(dir, dir, &mut out)?;
    out.sort();
    Ok(out)
}

fn file_entry(shown: String, p: &Path) -> std::io::Result<serde_json::Value> {
    let (sha, size) = sha256_file(p)?;
    Ok(serde_json::json!({ "path": shown, "sha256": sha, "size": size }))
}

/// Whether process `pid` is running (Linux: `/proc/<pid>` exists; elsewhere assumed running).
fn pid_alive(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        Path::new("/proc").join(pid.to_string()).exists()
    } else {
        true
    }
}

/// This machine's host name (empty when unknown): a lock written on another host of a cluster
/// cannot be checked with `/proc` here.
fn host_name() -> String {
    fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|s| s.trim().to_string())
        .or_else(|_| std::env::var("HOSTNAME"))
        .unwrap_or_default()
}

/// Who holds a lock file, as read from it.
#[derive(Clone, Debug, PartialEq)]
pub enum LockHolder {
    /// A running process (or one on another host, which cannot be checked from here).
    Live { pid: u32, host: String },
    /// A process that is no longer running.
    Stale { pid: u32 },
    /// The file holds no pid.
    Unreadable,
}

impl LockHolder {
    /// `pid 123` or `pid 123 on host h` (another host).
    pub fn describe(pid: u32, host: &str) -> String {
        if host.is_empty() || host == host_name() {
            format!("pid {pid}")
        } else {
            format!("pid {pid} on host {host}")
        }
    }
}

/// Reads the lock file `lock`: its first line is the pid, its second (optional) the host.
pub fn lock_holder(lock: &Path) -> LockHolder {
    let text = fs::read_to_string(lock).unwrap_or_default();
    let mut lines = text.lines();
    let Some(Ok(pid)) = lines.next().map(|l| l.trim().parse::<u32>()) else {
        return LockHolder::Unreadable;
    };
    let host = lines.next().unwrap_or("").trim().to_string();
    if (host.is_empty() || host == host_name()) && !pid_alive(pid) {
        LockHolder::Stale { pid }
    } else {
        LockHolder::Live { pid, host }
    }
}

/// A lock file held until dropped (then removed).
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
    /// Set when a stale lock (its process gone) was taken over: say so to the user.
    pub took_over: Option<String>,
}

impl FolderLock {
    /// Takes the lock file `lock` of folder `target`: created exclusively and holding our pid
    /// and host. A lock whose pid is no longer running on this host is stale and taken over.
    pub fn acquire(target: &Path, lock: &Path) -> Result<Self, OutputError> {
        use std::io::Write;
        let werr = |source| OutputError::Write {
            path: lock.to_path_buf(),
            source,
        };
        let mut took_over = None;
        for _ in 0..2 {
            match fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(lock)
            {
                Ok(mut f) => {
                    let held = Self {
                        path: lock.to_path_buf(),
                        took_over,
                    };
                    writeln!(f, "{}\n{}", std::process::id(), host_name()).map_err(werr)?;
                    return Ok(held);
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    match lock_holder(lock) {
                        LockHolder::Live { pid, host } => {
                            return Err(OutputError::Locked {
                                path: target.to_path_buf(),
                                holder: LockHolder::describe(pid, &host),
                                lock: lock.to_path_buf(),
                            })
                        }
                        LockHolder::Stale { pid } => {
                            // its process is gone: nobody writes under this lock any more
                            let _ = fs::remove_file(lock);
                            took_over = Some(format!(
                                "took over the stale lock file {} of pid {pid} (no longer running)",
                                lock.display()
                            ));
                        }
                        LockHolder::Unreadable => {
                            return Err(OutputError::BadLock {
                                path: target.to_path_buf(),
                                lock: lock.to_path_buf(),
                            })
                        }
                    }
                }
                Err(source) => return Err(werr(source)),
            }
        }
        Err(werr(std::io::Error::other(
            "another run took the lock over at the same time",
        )))
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        let _ = fs::remove_file(&self.path);
    }
}

/// A result folder being written: files go to a staging sibling that is published at
/// `path` (with `manifest.json`) by [`OutDir::finish`] (complete) or, when the job ends
/// otherwise (the value is dropped), with `complete: false` and the `INCOMPLETE` marker.
#[derive(Debug)]
pub struct OutDir {
    /// Final path.
    target: PathBuf,
    /// Where the files are written until publication.
    staging: PathBuf,
    /// Lock (top-level folders; a nested folder is covered by its parent's). Released after
    /// the folder is published (fields drop after `Drop::drop`).
    lock: Option<FolderLock>,
    run_id: String,
    start: SystemTime,
    inputs: Vec<serde_json::Value>,
    published: bool,
}

impl OutDir {
    /// Where the results come from, as the manifest records it: `run_id`, `rotorsim_version`,
    /// `git_commit`, `command_line` and `inputs` (path, sha256, size). Also written into a
    /// command's own summary so that it can travel alone.
    pub fn provenance(&self) -> serde_json::Value {
        serde_json::json!({
            "run_id": self.run_id,
            "rotorsim_version": env!("CARGO_PKG_VERSION"),
            "git_commit": GIT_COMMIT,
            "command_line": std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect::<Vec<_>>(),
            "inputs": self.inputs,
        })
    }

    /// Starts a result folder at `path`: takes its lock, removes stale staging siblings of
    /// earlier killed runs, records the sha256 of `inputs` (files; a directory stands for every
    /// file under it) and creates the staging folder with an `INCOMPLETE` marker. An existing
    /// folder at `path` is left untouched until publication; it must be empty or a rotorsim
    /// result folder (holding `manifest.json` or `INCOMPLETE`).
    pub fn create(path: &Path, inputs: &[PathBuf]) -> Result<Self, OutputError> {
        let invalid = |msg: &str| OutputError::Invalid {
            path: path.to_path_buf(),
            msg: msg.into(),
        };
        let name = path
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .ok_or_else(|| invalid("the folder needs a name (not `.`, `..` or a root)"))?;
        let parent = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let start = SystemTime::now();
        let run_id = new_run_id(start);
        let mut hashed = Vec::new();
        for p in inputs {
            let rerr = |source| OutputError::ReadInput {
                path: p.clone(),
                source,
            };
            if p.is_dir() {
                for (_, f) in walk_files(p).map_err(rerr)? {
                    hashed.push(file_entry(f.display().to_string(), &f).map_err(rerr)?);
                }
            } else {
                hashed.push(file_entry(p.display().to_string(), p).map_err(rerr)?);
            }
        }
        fs::create_dir_all(&parent).map_err(|source| OutputError::CreateDir {
            path: parent.clone(),
            source,
        })?;
        let lock = FolderLock::acquire(path, &parent.join(format!(".{name}.lock")))?;
        // From here the lock is released by Drop.
        let dir = Self {
            target: path.to_path_buf(),
            staging: parent.join(format!(".{name}.staging-{run_id}")),
            lock: Some(lock),
            run_id,
            start,
            inputs: hashed,
            published: true,
        };
        match fs::symlink_metadata(path) {
            Err(_) => {}
            Ok(m) if !m.is_dir() => return Err(invalid("exists and is not a folder")),
            Ok(_) => {
                let names: Vec<_> = fs::read_dir(path)
                    .map_err(|source| OutputError::CreateDir {
                        path: path.to_path_buf(),
                        source,
                    })?
                    .filter_map(|e| e.ok().map(|e| e.file_name()))
                    .collect();
                if !names.is_empty()
                    && !names
                        .iter()
                        .any(|n| n == MANIFEST || n == INCOMPLETE_MARKER)
                {
                    return Err(invalid(
                        "exists and is not a rotorsim result folder (no manifest.json): it would be replaced; remove it or choose another output folder",
                    ));
                }
            }
        }
        // Staging and trash siblings left by killed runs: no run holds them (we hold the lock).
        if let Ok(rd) = fs::read_dir(&parent) {
            let stale = [format!(".{name}.staging-"), format!(".{name}.trash-")];
            for e in rd.flatten() {
                let n = e.file_name().to_string_lossy().into_owned();
                if stale.iter().any(|s| n.starts_with(s.as_str())) {
                    let _ = fs::remove_dir_all(e.path());
                }
            }
        }
        fs::create_dir_all(&dir.staging).map_err(|source| OutputError::CreateDir {
            path: dir.staging.clone(),
            source,
        })?;
        if let Err(e) = dir.mark_incomplete("job started, not finished") {
            // nothing was written yet (full disk, read-only folder): leave no staging behind
            let _ = fs::remove_dir_all(&dir.staging);
            return Err(e);
        }
        let mut dir = dir;
        dir.published = false;
        Ok(dir)
    }

    /// A result folder nested in this one (`rel`, e.g. `rotor_check/baseline`): staged inside
    /// this folder's staging folder, with its own `manifest.json` and marker, published with it.
    pub fn sub_dir(&self, rel: &str) -> Result<OutDir, OutputError> {
        let dir = OutDir {
            target: self.target.join(rel),
            staging: self.staging.join(rel),
            lock: None,
            run_id: self.run_id.clone(),
            start: SystemTime::now(),
            inputs: self.inputs.clone(),
            published: false,
        };
        fs::create_dir_all(&dir.staging).map_err(|source| OutputError::CreateDir {
            path: dir.staging.clone(),
            source,
        })?;
        dir.mark_incomplete("job started, not finished")?;
        Ok(dir)
    }

    /// The folder's final path (where it is published).
    pub fn path(&self) -> &Path {
        &self.target
    }

    /// Final path of a file of the folder (for messages; it exists once published).
    pub fn file(&self, name: &str) -> PathBuf {
        self.target.join(name)
    }

    /// The staging folder the files are written to until publication.
    pub fn staging_path(&self) -> &Path {
        &self.staging
    }

    /// The final path of `p`, a path inside the staging folder (other paths are returned as
    /// they are).
    pub fn published_path(&self, p: &Path) -> PathBuf {
        match p.strip_prefix(&self.staging) {
            Ok(rel) => self.target.join(rel),
            Err(_) => p.to_path_buf(),
        }
    }

    /// The run id recorded in the manifest.
    pub fn run_id(&self) -> &str {
        &self.run_id
    }

    /// Writes one file of the folder atomically; returns where it is now (in the staging
    /// folder until publication, see [`OutDir::published_path`]).
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<PathBuf, OutputError> {
        let p = self.staging.join(name);
        write_atomic(&p, bytes)?;
        Ok(p)
    }

    /// Rewrites the marker with a reason (e.g. the numerical failure that stopped the job).
    pub fn mark_incomplete(&self, reason: &str) -> Result<(), OutputError> {
        write_atomic(
            &self.staging.join(INCOMPLETE_MARKER),
            format!("{reason}\n").as_bytes(),
        )
    }

    /// Removes the marker and publishes the folder as complete.
    pub fn finish(mut self) -> Result<(), OutputError> {
        let marker = self.staging.join(INCOMPLETE_MARKER);
        match fs::remove_file(&marker) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(source) => {
                return Err(OutputError::Write {
                    path: marker,
                    source,
                })
            }
        }
        self.publish(true)
    }

    /// Writes the manifest into the staging folder and (top-level folders) renames the staging
    /// folder to the final path, an earlier folder there moved aside and then removed.
    fn publish(&mut self, complete: bool) -> Result<(), OutputError> {
        self.published = true;
        match self.publish_inner(complete) {
            // a top-level folder that could not be published (full disk, read-only target)
            // stays in its staging sibling: name it (the next run into the folder removes it)
            Err(e @ OutputError::Publish { .. }) => Err(e),
            Err(e) if self.lock.is_some() => Err(OutputError::Publish {
                path: self.target.clone(),
                staging: self.staging.clone(),
                source: std::io::Error::other(e.to_string()),
            }),
            r => r,
        }
    }

    fn publish_inner(&mut self, complete: bool) -> Result<(), OutputError> {
        let marker = self.staging.join(INCOMPLETE_MARKER);
        let reason = if complete {
            None
        } else {
            if !marker.exists() {
                self.mark_incomplete("job stopped before it finished")?;
            }
            Some(
                fs::read_to_string(&marker)
                    .unwrap_or_default()
                    .trim_end()
                    .to_string(),
            )
        };
        let werr = |path: &Path| {
            let path = path.to_path_buf();
            move |source| OutputError::Write { path, source }
        };
        let mut outputs = Vec::new();
        for (rel, p) in walk_files(&self.staging).map_err(werr(&self.staging))? {
            if rel != MANIFEST {
                outputs.push(file_entry(rel, &p).map_err(werr(&p))?);
            }
        }
        let mut manifest = serde_json::json!({
            "run_id": self.run_id,
            "start_time": rfc3339(self.start),
            "end_time": rfc3339(SystemTime::now()),
            "complete": complete,
            "incomplete_reason": reason,
        });
        if let (Some(m), serde_json::Value::Object(p)) =
            (manifest.as_object_mut(), self.provenance())
        {
            m.extend(p);
            m.insert("outputs".into(), serde_json::Value::Array(outputs));
        }
        let text = serde_json::to_string_pretty(&manifest).map_err(|e| OutputError::Write {
            path: self.staging.join(MANIFEST),
            source: std::io::Error::other(e),
        })?;
        write_atomic(&self.staging.join(MANIFEST), text.as_bytes())?;
        if self.lock.is_none() {
            return Ok(()); // nested: published with its parent
        }
        let perr = |source| OutputError::Publish {
            path: self.target.clone(),
            staging: self.staging.clone(),
            source,
        };
        let trash = self.staging.with_file_name(
            self.staging
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .replacen(".staging-", ".trash-", 1),
        );
        let had_old = fs::symlink_metadata(&self.target).is_ok();
        if had_old {
            fs::rename(&self.target, &trash).map_err(perr)?;
        }
        if let Err(e) = fs::rename(&self.staging, &self.target) {
            if had_old {
                let _ = fs::rename(&trash, &self.target);
            }
            return Err(perr(e));
        }
        if had_old {
            // a failure leaves a trash sibling, removed by the next run into this folder
            let _ = fs::remove_dir_all(&trash);
        }
        Ok(())
    }
}

impl Drop for OutDir {
    fn drop(&mut self) {
        if !self.published {
            // The job ended without finish(): publish what it wrote, marked incomplete.
            let _ = self.publish(false);
        }
    }
}

/// Checks a published result folder against its manifest.json: the manifest parses and says
/// `complete` (true or false), every listed output is present with its size and sha256, and
/// the folder holds no file the manifest does not list. Returns the manifest, or why the
/// folder cannot be trusted (naming the file, relative to the folder).
pub fn verify_folder(dir: &Path) -> Result<serde_json::Value, String> {
    let text = fs::read_to_string(dir.join(MANIFEST))
        .map_err(|e| format!("{MANIFEST} cannot be read ({e})"))?;
    let m: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| format!("{MANIFEST} is not a manifest (not JSON: {e})"))?;
    if !m["complete"].is_boolean() {
        return Err(format!(
            "{MANIFEST} is not a manifest (`complete` missing or not true/false)"
        ));
    }
    let listed = m["outputs"]
        .as_array()
        .ok_or_else(|| format!("{MANIFEST} is not a manifest (`outputs` missing or not a list)"))?;
    let mut paths = Vec::with_capacity(listed.len());
    for o in listed {
        let (Some(rel), Some(sha), Some(size)) =
            (o["path"].as_str(), o["sha256"].as_str(), o["size"].as_u64())
        else {
            return Err(format!(
                "{MANIFEST} is not a manifest (an `outputs` entry lacks path, sha256 or size: {o})"
            ));
        };
        // the listed path stays inside the folder
        if rel.is_empty()
            || rel.starts_with('/')
            || rel.split('/').any(|c| c == ".." || c.is_empty())
        {
            return Err(format!(
                "{MANIFEST} lists an output outside the folder: {rel}"
            ));
        }
        let p = dir.join(rel);
        let meta =
            fs::metadata(&p).map_err(|_| format!("{rel} is listed in its manifest but missing"))?;
        if meta.len() != size {
            return Err(format!(
                "{rel} size differs from its manifest ({} bytes, listed as {size}): file changed after the run",
                meta.len()
            ));
        }
        let (got, _) = sha256_file(&p).map_err(|e| format!("{rel} cannot be read ({e})"))?;
        if got != sha {
            return Err(format!(
                "{rel} sha256 differs from its manifest (file changed after the run)"
            ));
        }
        paths.push(rel);
    }
    paths.sort_unstable();
    let files = walk_files(dir).map_err(|e| format!("cannot list the folder ({e})"))?;
    if let Some((rel, _)) = files
        .iter()
        .find(|(rel, _)| rel != MANIFEST && paths.binary_search(&rel.as_str()).is_err())
    {
        return Err(format!(
            "{rel} is not listed in its manifest (added after the run)"
        ));
    }
    Ok(m)
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

    fn tmp(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rotorsim-io-{tag}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<_> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn staged_publication_replaces_the_earlier_folder() {
        let root = tmp("publish");
        let dir = root.join("out");
        let input = root.join("in.txt");
        fs::write(&input, b"abc").unwrap();
        let out = OutDir::create(&dir, std::slice::from_ref(&input)).unwrap();
        assert!(
            !dir.exists(),
            "nothing at the final path before publication"
        );
        assert!(out.staging_path().join(INCOMPLETE_MARKER).exists());
        out.write("old.csv", b"x\n1\n").unwrap();
        out.finish().unwrap();
        assert_eq!(names(&dir), ["manifest.json", "old.csv"]);
        let out = OutDir::create(&dir, &[input]).unwrap();
        let p = out.write("sub/a.csv", b"x\n2\n").unwrap();
        assert_eq!(out.published_path(&p), dir.join("sub/a.csv"));
        out.finish().unwrap();
        assert_eq!(names(&dir), ["manifest.json", "sub"]);
        // only the folder and no lock, staging or trash sibling is left
        assert_eq!(names(&root), ["in.txt", "out"]);
        let m: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(dir.join(MANIFEST)).unwrap()).unwrap();
        assert_eq!(m["complete"], true);
        assert_eq!(m["outputs"][0]["path"], "sub/a.csv");
        assert_eq!(m["outputs"].as_array().unwrap().len(), 1);
        // sha256("abc")
        assert_eq!(
            m["inputs"][0]["sha256"],
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_dropped_folder_is_published_incomplete_and_a_live_lock_refuses() {
        let root = tmp("drop");
        let dir = root.join("out");
        {
            let out = OutDir::create(&dir, &[]).unwrap();
            out.write("a.csv", b"1\n").unwrap();
            out.mark_incomplete("model failed").unwrap();
            let e = OutDir::create(&dir, &[]).unwrap_err();
            assert!(matches!(e, OutputError::Locked { .. }), "{e}");
        }
        assert_eq!(names(&dir), ["INCOMPLETE", "a.csv", "manifest.json"]);
        let m: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(dir.join(MANIFEST)).unwrap()).unwrap();
        assert_eq!(m["complete"], false);
        assert_eq!(m["incomplete_reason"], "model failed");
        // a stale lock (dead pid) is taken over
        fs::write(root.join(".out.lock"), "999999999\n").unwrap();
        OutDir::create(&dir, &[]).unwrap().finish().unwrap();
        assert_eq!(names(&root), ["out"]);
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_folder_is_checked_against_its_manifest() {
        let root = tmp("verify");
        let dir = root.join("out");
        let out = OutDir::create(&dir, &[]).unwrap();
        out.write("summary.json", b"{\"x\": 1}").unwrap();
        out.write("m/last_rev.csv", b"a\n1\n").unwrap();
        out.finish().unwrap();
        assert_eq!(verify_folder(&dir).unwrap()["complete"], true);
        // same size, other bytes
        fs::write(dir.join("summary.json"), b"{\"x\": 2}").unwrap();
        let e = verify_folder(&dir).unwrap_err();
        assert_eq!(
            e,
            "summary.json sha256 differs from its manifest (file changed after the run)"
        );
        fs::write(dir.join("summary.json"), b"{\"x\": 10}").unwrap();
        assert!(verify_folder(&dir)
            .unwrap_err()
            .contains("summary.json size differs from its manifest (9 bytes, listed as 8)"));
        fs::write(dir.join("summary.json"), b"{\"x\": 1}").unwrap();
        fs::write(dir.join("extra.json"), b"{}").unwrap();
        assert!(verify_folder(&dir)
            .unwrap_err()
            .contains("extra.json is not listed"));
        fs::remove_file(dir.join("extra.json")).unwrap();
        fs::remove_file(dir.join("m/last_rev.csv")).unwrap();
        assert!(verify_folder(&dir)
            .unwrap_err()
            .contains("m/last_rev.csv is listed in its manifest but missing"));
        fs::write(dir.join(MANIFEST), b"garbage").unwrap();
        assert!(verify_folder(&dir).unwrap_err().contains("not JSON"));
        fs::write(dir.join(MANIFEST), b"{\"complete\": true}").unwrap();
        assert!(verify_folder(&dir).unwrap_err().contains("`outputs`"));
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_stale_lock_is_taken_over_with_a_note() {
        let root = tmp("lock");
        let lock = root.join(".x.lock");
        fs::write(&lock, "999999999\n").unwrap();
        let held = FolderLock::acquire(&root, &lock).unwrap();
        assert!(held.took_over.as_deref().unwrap().contains("pid 999999999"));
        assert_eq!(
            lock_holder(&lock),
            LockHolder::Live {
                pid: std::process::id(),
                host: host_name()
            }
        );
        let e = FolderLock::acquire(&root, &lock).unwrap_err().to_string();
        assert!(e.contains(&format!("pid {}", std::process::id())), "{e}");
        drop(held);
        assert!(!lock.exists());
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_foreign_folder_is_not_replaced() {
        let root = tmp("foreign");
        fs::write(root.join("notes.txt"), b"mine").unwrap();
        let e = OutDir::create(&root, &[]).unwrap_err();
        assert!(
            e.to_string().contains("not a rotorsim result folder"),
            "{e}"
        );
        assert!(root.join("notes.txt").exists());
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn rfc3339_from_system_time() {
        let t = |s: u64, ms: u64| UNIX_EPOCH + std::time::Duration::from_millis(s * 1000 + ms);
        assert_eq!(rfc3339(t(0, 0)), "1970-01-01T00:00:00.000Z");
        assert_eq!(rfc3339(t(951_782_400, 5)), "2000-02-29T00:00:00.005Z");
        assert_eq!(rfc3339(t(1_700_000_000, 0)), "2023-11-14T22:13:20.000Z");
        assert_eq!(rfc3339(t(4_107_542_399, 999)), "2100-02-28T23:59:59.999Z");
        assert_eq!(rfc3339(t(1_709_251_199, 0)), "2024-02-29T23:59:59.000Z");
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
