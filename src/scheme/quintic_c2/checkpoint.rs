//! Exploration: the hole repair's progress saved to a file as it goes and taken up again from
//! it (`APATCH_HOLE_CHECKPOINT=repair.ckpt`), so that a repair longer than one sitting (fandisk's
//! takes hours) is not lost when its process ends.
//!
//! The file holds the slot values after the last decided wave of repairs, the pass it belongs
//! to, the defects that pass has decided (kept or refused) and the counts so far. Taken up
//! again, the repair skips the passes before, and the decided defects of that pass, and goes on
//! from the saved values. As the repairs of a pass are decided in defect order on the values
//! the earlier ones left (the waves give the one-by-one result), a run taken up again gives the
//! uninterrupted run's result, bit for bit. The file must come from the same scene and solve:
//! the slot count and the defect list found at the start are checked.
//!
//! The file also holds the repair's plan, the reach of each of its passes (format 2), so that a
//! repair can be taken up with more passes than it was started with (`repair_widen` raised):
//! the passes done and the one under way must be the same, else the file is refused. A file of
//! format 1 (no plan) is taken up by its pass number alone.
//!
//! The file is written beside its name and renamed over it, so a process stopped while
//! writing leaves the previous checkpoint whole.

use super::holes::HoleRepair;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// The environment variable naming the checkpoint file.
pub const CHECKPOINT_VAR: &str = "APATCH_HOLE_CHECKPOINT";
/// First bytes of a checkpoint: format version 2, with the plan.
const MAGIC: &[u8; 8] = b"APHCKPT2";
/// First bytes of a checkpoint of format version 1 (no plan), still read.
const MAGIC_1: &[u8; 8] = b"APHCKPT1";

/// The checkpoint named by [`CHECKPOINT_VAR`], if set.
#[must_use]
pub fn requested() -> Option<PathBuf> {
    std::env::var_os(CHECKPOINT_VAR).map(Into::into)
}

/// Exploration and tests: with `APATCH_HOLE_STOP_AFTER=n` the repair stops after `n` waves
/// of repairs (saving its checkpoint), as if its process had ended there; `n = 0` runs none,
/// so that a checkpoint taken up with it gives its values as a complex (to `check` a long
/// repair's progress without stopping it).
#[must_use]
pub fn stop_after() -> Option<usize> {
    std::env::var("APATCH_HOLE_STOP_AFTER").ok()?.parse().ok()
}

/// Test hooks for checkpoints within a wave of repairs: `APATCH_HOLE_CHECKPOINT_EVERY=s` saves
/// at most every `s` seconds instead of `default`'s, and `APATCH_HOLE_EXIT_AFTER=n` ends the
/// process (exit status 3, nothing written but the checkpoint) once `n` repairs of a wave are
/// saved, as a process killed midway would.
#[must_use]
pub fn midway_hooks(default: std::time::Duration) -> (std::time::Duration, Option<usize>) {
    let every = std::env::var("APATCH_HOLE_CHECKPOINT_EVERY")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(default, std::time::Duration::from_secs);
    let exit_after = std::env::var("APATCH_HOLE_EXIT_AFTER")
        .ok()
        .and_then(|v| v.parse().ok());
    (every, exit_after)
}

/// A repair's progress.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// A fingerprint of the defects found at the start ([`fingerprint`]).
    pub defects: u64,
    /// The pass under way (0 = the first; the plan's length when every pass is done).
    pub pass: usize,
    /// The reach of every pass of the repair's plan, as (rings, Hessians free); empty when
    /// read from a file of format 1, which did not keep it.
    pub plan: Vec<(usize, bool)>,
    /// Defects (indices into the start's list) that pass has decided.
    pub decided: Vec<u32>,
    /// The counts of the repairs kept so far.
    pub counts: HoleRepair,
    /// Every slot's value after the decided repairs.
    pub value: Vec<f64>,
}

/// A fingerprint of a defect list (each defect as (tetrahedron, local vertex)): FNV-1a over
/// the pairs, with the count.
#[must_use]
pub fn fingerprint(defects: impl IntoIterator<Item = (u32, usize)>) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut n = 0u64;
    for (t, v) in defects {
        for b in t.to_le_bytes().into_iter().chain((v as u32).to_le_bytes()) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
        n += 1;
    }
    h ^ n.rotate_left(32)
}

/// The counts a checkpoint keeps, in file order.
fn counts_of(c: &HoleRepair) -> [usize; 6] {
    [
        c.repaired,
        c.sheets_repaired,
        c.pinned,
        c.widened,
        c.soft,
        c.hessian,
    ]
}

/// Writes `p` to `path` (through a file beside it, renamed over it).
///
/// # Errors
/// An input error naming `path` when it cannot be written.
pub fn save(path: &Path, p: &Progress) -> Result<()> {
    let mut b = Vec::with_capacity(64 + 4 * p.decided.len() + 8 * p.value.len());
    b.extend_from_slice(MAGIC);
    b.extend_from_slice(&p.defects.to_le_bytes());
    b.extend_from_slice(&(p.pass as u64).to_le_bytes());
    b.extend_from_slice(&(p.plan.len() as u64).to_le_bytes());
    for &(rings, hessians) in &p.plan {
        b.extend_from_slice(&(rings as u64).to_le_bytes());
        b.extend_from_slice(&u64::from(hessians).to_le_bytes());
    }
    for c in counts_of(&p.counts) {
        b.extend_from_slice(&(c as u64).to_le_bytes());
    }
    b.extend_from_slice(&(p.decided.len() as u64).to_le_bytes());
    for d in &p.decided {
        b.extend_from_slice(&d.to_le_bytes());
    }
    b.extend_from_slice(&(p.value.len() as u64).to_le_bytes());
    for v in &p.value {
        b.extend_from_slice(&v.to_le_bytes());
    }
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".part");
    let tmp = PathBuf::from(tmp);
    let io = |e: std::io::Error| Error::Input {
        path: path.to_path_buf(),
        message: format!("cannot write the hole repair checkpoint: {e}"),
    };
    std::fs::write(&tmp, &b).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(io)
}

/// The progress saved at `path`, or `None` when there is no such file yet.
///
/// # Errors
/// An input error naming `path` when it cannot be read, is not a checkpoint, or does not fit
/// a repair of `slots` slots whose defects have the fingerprint `defects`.
pub fn load(path: &Path, slots: usize, defects: u64) -> Result<Option<Progress>> {
    let bad = |message: String| Error::Input {
        path: path.to_path_buf(),
        message: format!(
            "{message} (`{CHECKPOINT_VAR}` needs a checkpoint of this scene's repair)"
        ),
    };
    let b = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(bad(format!("cannot read: {e}"))),
    };
    let mut r = Reader { b: &b, at: 0 };
    let short = || bad("the checkpoint ends early".into());
    let version = match r.bytes(8).ok_or_else(short)? {
        m if m == MAGIC => 2,
        m if m == MAGIC_1 => 1,
        _ => return Err(bad("not a hole repair checkpoint".into())),
    };
    if r.u64().ok_or_else(short)? != defects {
        return Err(bad("its defects are not the ones this solve leaves".into()));
    }
    let pass = r.u64().ok_or_else(short)? as usize;
    let mut plan = Vec::new();
    if version == 2 {
        let n = r.u64().ok_or_else(short)? as usize;
        for _ in 0..n {
            let rings = r.u64().ok_or_else(short)? as usize;
            let hessians = match r.u64().ok_or_else(short)? {
                0 => false,
                1 => true,
                h => return Err(bad(format!("a pass's Hessian flag is {h}, not 0 or 1"))),
            };
            plan.push((rings, hessians));
        }
        if pass > plan.len() {
            return Err(bad(format!("pass {pass} of a plan of {}", plan.len())));
        }
    }
    let mut c = [0usize; 6];
    for x in &mut c {
        *x = r.u64().ok_or_else(short)? as usize;
    }
    let counts = HoleRepair {
        repaired: c[0],
        sheets_repaired: c[1],
        pinned: c[2],
        widened: c[3],
        soft: c[4],
        hessian: c[5],
        ..HoleRepair::default()
    };
    let nd = r.u64().ok_or_else(short)? as usize;
    let decided = (0..nd)
        .map(|_| {
            r.bytes(4)
                .map(|x| u32::from_le_bytes(x.try_into().expect("4 bytes")))
        })
        .collect::<Option<Vec<u32>>>()
        .ok_or_else(short)?;
    let nv = r.u64().ok_or_else(short)? as usize;
    if nv != slots {
        return Err(bad(format!("{nv} slots, the scene has {slots}")));
    }
    let value = (0..nv)
        .map(|_| r.u64().map(f64::from_bits))
        .collect::<Option<Vec<f64>>>()
        .ok_or_else(short)?;
    if r.at != b.len() {
        return Err(bad("bytes after the checkpoint's end".into()));
    }
    Ok(Some(Progress {
        defects,
        pass,
        plan,
        decided,
        counts,
        value,
    }))
}

/// Whether the progress `p` read from `path` can be taken up by a repair whose passes are
/// `plan`: the passes it finished and the one under way must be the same (more passes after
/// them are fine). A file without a plan (format 1) is taken up by its pass number alone.
///
/// # Errors
/// An input error naming `path` and the first pass that differs.
pub fn check_plan(path: &Path, p: &Progress, plan: &[(usize, bool)]) -> Result<()> {
    if p.plan.is_empty() {
        return Ok(());
    }
    let upto = (p.pass + 1).min(p.plan.len());
    let show = |r: Option<&(usize, bool)>| match r {
        Some(&(rings, true)) => format!("{rings} rings, Hessians free"),
        Some(&(rings, false)) => format!("{rings} rings"),
        None => "none".to_string(),
    };
    match (0..upto).find(|&k| plan.get(k) != p.plan.get(k)) {
        None => Ok(()),
        Some(k) => Err(Error::Input {
            path: path.to_path_buf(),
            message: format!(
                "the checkpoint's pass {} ({}) is not this scene's ({}): a repair can be taken up only with the same passes, more after them (`{CHECKPOINT_VAR}`)",
                k + 1,
                show(p.plan.get(k)),
                show(plan.get(k))
            ),
        }),
    }
}

/// Little-endian fields read in turn from a checkpoint's bytes.
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn bytes(&mut self, n: usize) -> Option<&[u8]> {
        let s = self.b.get(self.at..self.at + n)?;
        self.at += n;
        Some(s)
    }

    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.bytes(8)?.try_into().ok()?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_checkpoint_reads_back_what_was_saved_and_refuses_another_repair() {
        let dir = std::env::temp_dir().join(format!("apatch_ckpt_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("r.ckpt");
        assert_eq!(
            load(&path, 3, 7).unwrap(),
            None,
            "no file yet: a fresh start"
        );
        let fp = fingerprint([(4, 1), (9, 4)]);
        let p = Progress {
            defects: fp,
            pass: 2,
            plan: vec![(2, false), (3, false), (4, true)],
            decided: vec![0, 5, 3],
            counts: HoleRepair {
                repaired: 11,
                sheets_repaired: 2,
                pinned: 40,
                widened: 1,
                soft: 3,
                hessian: 0,
                ..HoleRepair::default()
            },
            // Values with every bit meaningful (a negative zero, a subnormal).
            value: vec![-0.0, 1.5e-310, 0.1 + 0.2],
        };
        save(&path, &p).unwrap();
        let q = load(&path, 3, fp).unwrap().unwrap();
        assert_eq!(q.pass, p.pass);
        assert_eq!(q.plan, p.plan);
        assert_eq!(q.decided, p.decided);
        assert_eq!(q.counts, p.counts);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&q.value), bits(&p.value));
        // Another defect list, another slot count, a cut file: input errors naming the file.
        assert_ne!(fp, fingerprint([(4, 1), (9, 3)]));
        for e in [
            load(&path, 3, fingerprint([(4, 1), (9, 3)])).unwrap_err(),
            load(&path, 4, fp).unwrap_err(),
        ] {
            assert!(e.to_string().contains("r.ckpt"), "{e}");
        }
        // The plan: the passes done and the one under way must match; more after them may
        // follow, and a file of format 1 (the same without its plan) is taken as it is.
        let longer = [(2, false), (3, false), (4, true), (5, true)];
        check_plan(&path, &q, &longer).unwrap();
        for other in [&longer[..2], &[(2, false), (3, true), (4, true)][..]] {
            let e = check_plan(&path, &q, other).unwrap_err().to_string();
            assert!(e.contains("r.ckpt") && e.contains("pass"), "{e}");
        }
        let b = std::fs::read(&path).unwrap();
        let mut v1 = b"APHCKPT1".to_vec();
        v1.extend_from_slice(&b[8..24]);
        v1.extend_from_slice(&b[24 + 8 + 16 * p.plan.len()..]);
        let old = dir.join("v1.ckpt");
        std::fs::write(&old, &v1).unwrap();
        let q1 = load(&old, 3, fp).unwrap().unwrap();
        assert_eq!((q1.pass, q1.plan.len()), (2, 0));
        assert_eq!((&q1.decided, &q1.counts), (&p.decided, &p.counts));
        assert_eq!(bits(&q1.value), bits(&p.value));
        check_plan(&old, &q1, &longer[..1]).unwrap();
        std::fs::write(&path, &b[..b.len() - 1]).unwrap();
        assert!(load(&path, 3, fp)
            .unwrap_err()
            .to_string()
            .contains("ends early"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
