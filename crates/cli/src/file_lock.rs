//! Advisory locks on the files drumroll appends to or resumes (a grid's part file, the
//! `.part` file an approach sweep streams into): one process at a time writes a file, and a
//! second one refuses at once, naming the file and, where the platform tells (Linux:
//! `/proc/locks`), the process holding it. The lock is `flock` (the `fs4` crate), released by
//! the system when the holder exits or is killed, so a killed run never leaves a stale lock.

use anyhow::{bail, Context, Result};
use std::fs::File;
use std::path::Path;

/// Take the exclusive lock of `file` (open at `path`, the value of `option`) without waiting;
/// if another process holds a lock on it, an error naming `option`, the file and that process.
pub fn lock_exclusive(file: &File, path: &Path, option: &str) -> Result<()> {
    let taken = try_lock(file, true)
        .with_context(|| format!("{option} {}: cannot lock it", path.display()))?;
    if !taken {
        bail!(
            "{option} {}: the file is being written by {}; a second writer would overwrite its \
             lines, so this one stops and leaves the file as it is. Wait for that process to \
             finish (or stop it), then run again",
            path.display(),
            holder_words(file)
        );
    }
    Ok(())
}

/// Take a shared lock of `file` (open at `path`) without waiting, for reading a file that a
/// writer may be appending to; an error naming the file and the writing process otherwise.
pub fn lock_shared(file: &File, path: &Path, what: &str) -> Result<()> {
    let taken = try_lock(file, false)
        .with_context(|| format!("{what} {}: cannot lock it", path.display()))?;
    if !taken {
        bail!(
            "{what} {}: the file is still being written by {}; wait for it to finish",
            path.display(),
            holder_words(file)
        );
    }
    Ok(())
}

/// Try to take the lock of `file` (`exclusive` or shared) without waiting: whether it was
/// taken.
#[cfg(not(target_arch = "wasm32"))]
fn try_lock(file: &File, exclusive: bool) -> std::io::Result<bool> {
    if exclusive {
        fs4::fs_std::FileExt::try_lock_exclusive(file)
    } else {
        fs4::fs_std::FileExt::try_lock_shared(file)
    }
}

/// WebAssembly (the explorer page): no other process shares the file system; always taken.
#[cfg(target_arch = "wasm32")]
fn try_lock(_file: &File, _exclusive: bool) -> std::io::Result<bool> {
    Ok(true)
}

/// "process 1234" (or "another process" where the holder cannot be told).
fn holder_words(file: &File) -> String {
    match holder_pid(file) {
        Some(pid) => format!("another drumroll process (PID {pid})"),
        None => String::from("another process"),
    }
}

/// The process holding a lock on `file`, read from `/proc/locks` (Linux), `None` elsewhere or
/// when it cannot be told.
#[cfg(target_os = "linux")]
pub fn holder_pid(file: &File) -> Option<u32> {
    use std::os::unix::fs::MetadataExt;
    let metadata = file.metadata().ok()?;
    let locks = std::fs::read_to_string("/proc/locks").ok()?;
    holder_in_proc_locks(&locks, metadata.dev(), metadata.ino(), std::process::id())
}

/// The process holding a lock on `file`: not told on this platform.
#[cfg(not(target_os = "linux"))]
pub fn holder_pid(_file: &File) -> Option<u32> {
    None
}

/// The PID of a lock (not a waiter, not `own_pid`) on the file of device `dev` and inode
/// `ino` in the text of `/proc/locks`, whose lines read
/// `1: FLOCK  ADVISORY  WRITE 4153 fd:01:1444003 0 EOF` (major and minor device numbers in
/// hexadecimal, the inode in decimal; a waiter's line has `->` after the number).
pub fn holder_in_proc_locks(locks: &str, dev: u64, ino: u64, own_pid: u32) -> Option<u32> {
    let major = ((dev >> 8) & 0xfff) | ((dev >> 32) & !0xfff);
    let minor = (dev & 0xff) | ((dev >> 12) & !0xff);
    locks.lines().find_map(|line| {
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.get(1) == Some(&"->") || words.len() < 6 {
            return None;
        }
        let pid: u32 = words[4].parse().ok()?;
        let mut id = words[5].split(':');
        let (m, n, i) = (id.next()?, id.next()?, id.next()?);
        let same = u64::from_str_radix(m, 16).ok()? == major
            && u64::from_str_radix(n, 16).ok()? == minor
            && i.parse::<u64>().ok()? == ino;
        (same && pid != own_pid).then_some(pid)
    })
}

/// Whether the open `file` is still the file at `path` (not removed or replaced meanwhile).
#[cfg(unix)]
pub fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Whether the open `file` is still the file at `path`: assumed on this platform.
#[cfg(not(unix))]
pub fn same_file(_file: &File, path: &Path) -> bool {
    path.exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_holder_is_read_from_proc_locks_lines() {
        // Device 253:1 (0xfd:0x01) is dev_t 0xfd01 in the kernel's encoding.
        let text = "1: FLOCK  ADVISORY  WRITE 4153 fd:01:1444003 0 EOF\n\
                    1: -> FLOCK  ADVISORY  WRITE 4200 fd:01:1444003 0 EOF\n\
                    2: POSIX  ADVISORY  WRITE 77 08:02:99 0 EOF\n";
        assert_eq!(holder_in_proc_locks(text, 0xfd01, 1_444_003, 1), Some(4153));
        assert_eq!(holder_in_proc_locks(text, 0x0802, 99, 1), Some(77));
        assert_eq!(holder_in_proc_locks(text, 0x0802, 98, 1), None);
        assert_eq!(holder_in_proc_locks(text, 0xfd01, 1_444_003, 4153), None);
    }
}
