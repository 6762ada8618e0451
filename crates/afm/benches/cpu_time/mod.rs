//! CPU clocks for the afm benchmarks (Linux `/proc`, nanosecond resolution), so that a figure
//! does not depend on other processes sharing the machine: the calling thread's, and the whole
//! process's (rayon's threads too). `None` where `/proc` cannot be read.

/// CPU time of the calling thread so far, seconds (`/proc/thread-self/schedstat`, first field):
/// the honest "one core" figure on a loaded machine, where wall time also counts the time
/// other processes held the core.
#[allow(dead_code)]
pub fn thread_cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let nanoseconds: f64 = text.split_whitespace().next()?.parse().ok()?;
    Some(nanoseconds * 1e-9)
}

/// CPU time so far of every thread of this process, seconds (the sum of
/// `/proc/self/task/*/schedstat`): the calling thread and rayon's, which the regime map's
/// curves and the fit's Jacobian run on (rayon's threads live as long as the process).
#[allow(dead_code)]
pub fn process_cpu_seconds() -> Option<f64> {
    let mut nanoseconds = 0.0;
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let text = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        nanoseconds += text.split_whitespace().next()?.parse::<f64>().ok()?;
    }
    Some(nanoseconds * 1e-9)
}
