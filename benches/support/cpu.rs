//! CPU time of the bench process, shared by the benches that report per-CPU-second figures
//! (on a shared, loaded machine wall time mostly measures the other processes).

/// CPU seconds (user + system) used by this process so far (Linux `/proc/self/stat`, 100
/// ticks/s), or NaN where that file is missing.
pub fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    let Some(rest) = stat.rsplit_once(')').map(|r| r.1) else {
        return f64::NAN;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let tick = |i: usize| {
        f.get(i)
            .and_then(|x| x.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    // Fields 14 and 15 (utime, stime) are at 11 and 12 after the command name.
    (tick(11) + tick(12)) / 100.0
}

/// The first three fields of `/proc/loadavg` (1, 5 and 15 minute load averages), or "?".
#[allow(dead_code)] // each bench includes this file; not every bench prints the load
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "?".into())
}

/// The median of `v` (the upper one for an even count); NaN for an empty `v`.
#[allow(dead_code)] // each bench includes this file; not every bench takes medians
pub fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
