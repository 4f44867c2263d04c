//! What this machine has, for the size checks of the commands and of the Python package:
//! the memory the kernel could give now, the free disk under a folder, and bytes shown as a
//! person reads them.

/// Bytes as a person reads them, one format throughout: 1.5 GB, 310.0 MB, 1.4 PB.
pub fn show_bytes(bytes: f64) -> String {
    // (Beyond a thousand EB, in powers of ten: 1e24 cells made "932000000000000.0 TB".)
    if bytes >= 1e21 {
        return format!("{bytes:.1e} B");
    }
    let units = [
        ("EB", 1e18),
        ("PB", 1e15),
        ("TB", 1e12),
        ("GB", 1e9),
        ("MB", 1e6),
        ("kB", 1e3),
    ];
    match units.iter().find(|(_, size)| bytes >= *size) {
        Some((name, size)) => format!("{:.1} {name}", bytes / size),
        None => format!("{bytes:.0} B"),
    }
}

/// Memory the kernel could give this process now, if it says: the least of the machine's
/// MemAvailable, what the process's control group may still use (cgroup v2 memory.max less
/// memory.current) and what its address-space limit (ulimit -v) leaves beyond its size now.
pub fn available_memory() -> Option<f64> {
    [
        machine_available(),
        cgroup_available(),
        address_space_available(),
    ]
    .into_iter()
    .flatten()
    .reduce(f64::min)
}

/// A "Key:   N kB" line of a /proc file, in bytes.
fn kb_field(text: &str, key: &str) -> Option<f64> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

fn machine_available() -> Option<f64> {
    kb_field(
        &std::fs::read_to_string("/proc/meminfo").ok()?,
        "MemAvailable:",
    )
}

/// memory.max − memory.current of this process's cgroup (v2), where it has a limit.
fn cgroup_available() -> Option<f64> {
    let cgroup = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let path = cgroup.lines().find_map(|l| l.strip_prefix("0::"))?;
    let dir = std::path::Path::new("/sys/fs/cgroup").join(path.trim_start_matches('/'));
    let read = |name: &str| -> Option<f64> {
        std::fs::read_to_string(dir.join(name))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    // "max" (no limit) does not parse.
    let max = read("memory.max")?;
    Some((max - read("memory.current").unwrap_or(0.0)).max(0.0))
}

/// RLIMIT_AS less the process's address space now (VmSize), where there is a limit.
fn address_space_available() -> Option<f64> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit fills the struct it is given.
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } != 0
        || limit.rlim_cur == libc::RLIM_INFINITY
    {
        return None;
    }
    let size = kb_field(
        &std::fs::read_to_string("/proc/self/status").ok()?,
        "VmSize:",
    )?;
    Some((limit.rlim_cur as f64 - size).max(0.0))
}

/// Free space for an unprivileged user in the folder that will hold `out` (None where the
/// file system does not say).
pub fn free_disk(out: &std::path::Path) -> Option<f64> {
    use std::os::unix::ffi::OsStrExt;
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => std::path::Path::new("."),
    };
    let c_path = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
    // SAFETY: statvfs fills the zeroed struct from a valid NUL-terminated path.
    let mut stat: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(c_path.as_ptr(), &mut stat) } != 0 {
        return None;
    }
    // A pseudo file system (/proc, /sys) has no blocks at all: it does not say, and writing
    // there fails with its own reason.
    if stat.f_blocks == 0 {
        return None;
    }
    Some(stat.f_bavail as f64 * stat.f_frsize as f64)
}

/// What is short when a request needs `bytes` of memory: over 80 % of what the kernel
/// could give now, as "about X of memory (Y available)"; None when it fits or the kernel
/// does not say.
pub fn memory_short(bytes: f64) -> Option<String> {
    let free = available_memory().filter(|&free| bytes > 0.8 * free)?;
    Some(format!(
        "about {} of memory ({} available)",
        show_bytes(bytes),
        show_bytes(free)
    ))
}

/// What is short when writing `bytes` beside `out`: more than the free disk there, as "up to
/// X of disk (Y free there)"; None when it fits or the file system does not say.
pub fn disk_short(bytes: f64, out: &std::path::Path) -> Option<String> {
    let free = free_disk(out).filter(|&free| bytes > free)?;
    Some(format!(
        "up to {} of disk ({} free there)",
        show_bytes(bytes),
        show_bytes(free)
    ))
}

/// Refuses a request that needs `bytes` of memory when that is over 80 % of what the kernel
/// could give now (unless `allow_large`): the one line says how much, what is available, and
/// `remedy`.
pub fn check_memory(bytes: f64, allow_large: bool, remedy: &str) -> crate::Result<()> {
    match memory_short(bytes) {
        Some(short) if !allow_large => Err(crate::AtlasError::TooLarge {
            reason: format!("needs {short}: {remedy}"),
        }),
        _ => Ok(()),
    }
}

/// The thread count `RAYON_NUM_THREADS` asks for, read as rayon reads it: unset, empty or 0 is
/// every core (`None`); anything but a whole number is refused in one line, not ignored as
/// rayon ignores it.
pub fn threads_from_env() -> crate::Result<Option<usize>> {
    match std::env::var("RAYON_NUM_THREADS") {
        Ok(v) if !v.trim().is_empty() => match v.trim().parse::<usize>() {
            Ok(n) => Ok(Some(n).filter(|&n| n > 0)),
            Err(_) => Err(crate::AtlasError::Atlas {
                path: format!("RAYON_NUM_THREADS = {v:?}"),
                reason: format!(
                    "must be a whole number of threads, at most {} (0 or unset: every core)",
                    usize::MAX
                ),
            }),
        },
        _ => Ok(None),
    }
}
