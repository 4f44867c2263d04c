//! What this machine has, for the size checks of the commands and of the Python package:
//! the memory the kernel could give now, the free disk under a folder, and bytes shown as a
//! person reads them.

/// Bytes as a person reads them, one format throughout: 1.5 GB, 310.0 MB.
pub fn show_bytes(bytes: f64) -> String {
    let units = [("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)];
    match units.iter().find(|(_, size)| bytes >= *size) {
        Some((name, size)) => format!("{:.1} {name}", bytes / size),
        None => format!("{bytes:.0} B"),
    }
}

/// Memory the kernel could give this process now (MemAvailable), if it says.
pub fn available_memory() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Free space for an unprivileged user in the folder that will hold `out`.
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
    Some(stat.f_bavail as f64 * stat.f_frsize as f64)
}

/// Refuses a request that needs `bytes` of memory when that is over 80 % of what the kernel
/// could give now (unless `allow_large`): the one line says how much, what is available, and
/// `remedy`.
pub fn check_memory(bytes: f64, allow_large: bool, remedy: &str) -> crate::Result<()> {
    match available_memory() {
        Some(free) if !allow_large && bytes > 0.8 * free => Err(crate::AtlasError::TooLarge {
            reason: format!(
                "needs about {} of memory ({} available): {remedy}",
                show_bytes(bytes),
                show_bytes(free)
            ),
        }),
        _ => Ok(()),
    }
}
