//! Resource limits and process attributes of the worker.

use std::io;

fn set(resource: libc::__rlimit_resource_t, soft: u64, hard: u64) -> io::Result<()> {
    let limit = libc::rlimit {
        rlim_cur: soft,
        rlim_max: hard,
    };
    // SAFETY: plain syscall with a valid struct.
    if unsafe { libc::setrlimit(resource, &limit) } != 0 {
        return Err(io::Error::last_os_error());
    }
    Ok(())
}

/// Limits applied before the interpreter starts: address space, CPU time, no core dumps.
pub(crate) fn before_startup(memory_bytes: u64, cpu_seconds: u64) -> io::Result<()> {
    set(libc::RLIMIT_CORE, 0, 0)?;
    set(libc::RLIMIT_AS, memory_bytes, memory_bytes)?;
    // SIGXCPU at the soft limit, SIGKILL one second later.
    set(libc::RLIMIT_CPU, cpu_seconds, cpu_seconds + 1)
}

/// Limits applied after start-up: no new files can be opened beyond the low descriptor
/// numbers in use, and no file can be written to at all.
pub(crate) fn after_startup() -> io::Result<()> {
    set(libc::RLIMIT_NOFILE, 16, 16)?;
    set(libc::RLIMIT_FSIZE, 0, 0)?;
    // SAFETY: prctl with integer arguments.
    if unsafe { libc::prctl(libc::PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) } != 0 {
        return Err(io::Error::last_os_error());
    }
    Ok(())
}

/// Asks the kernel to SIGKILL this process when its parent dies; exits if the parent is
/// already gone.
pub(crate) fn die_with_parent(expected_parent: libc::pid_t) {
    // SAFETY: prctl/getppid/_exit are async-signal-safe syscalls.
    unsafe {
        libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL, 0, 0, 0);
        if libc::getppid() != expected_parent {
            libc::_exit(1);
        }
    }
}
