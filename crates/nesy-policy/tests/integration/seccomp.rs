//! The worker's seccomp filter, checked in a forked child: after installing it, starting a
//! program, forking, opening a socket and opening a file for writing all fail with EPERM,
//! while reading files still works.

#![cfg(target_arch = "x86_64")]

fn errno() -> i32 {
    std::io::Error::last_os_error().raw_os_error().unwrap_or(0)
}

#[test]
fn filter_refuses_exec_fork_sockets_and_writes() {
    let dir = tempfile::tempdir().unwrap();
    let target = std::ffi::CString::new(dir.path().join("written").to_str().unwrap()).unwrap();
    // SAFETY: the child only makes raw system calls and exits with _exit.
    let pid = unsafe { libc::fork() };
    assert!(pid >= 0);
    if pid == 0 {
        let mut failures = 0u8;
        // SAFETY: raw system calls in the forked child.
        unsafe {
            if nesy_policy::install_seccomp_filter().is_err() {
                libc::_exit(100);
            }
            if libc::socket(libc::AF_INET, libc::SOCK_STREAM, 0) >= 0 || errno() != libc::EPERM {
                failures |= 1;
            }
            let argv = [c"/bin/true".as_ptr(), std::ptr::null()];
            let envp = [std::ptr::null()];
            if libc::execve(c"/bin/true".as_ptr(), argv.as_ptr(), envp.as_ptr()) == 0
                || errno() != libc::EPERM
            {
                failures |= 2;
            }
            if libc::syscall(libc::SYS_fork) >= 0 || errno() != libc::EPERM {
                failures |= 4;
            }
            let fd = libc::open(target.as_ptr(), libc::O_WRONLY | libc::O_CREAT, 0o600);
            if fd >= 0 || errno() != libc::EPERM {
                failures |= 8;
            }
            if libc::open(c"/proc/self/status".as_ptr(), libc::O_RDONLY) < 0 {
                failures |= 16;
            }
            libc::_exit(failures as i32);
        }
    }
    let mut status = 0;
    // SAFETY: waiting for our own child.
    unsafe { libc::waitpid(pid, &mut status, 0) };
    assert!(libc::WIFEXITED(status), "child died: {status}");
    assert_eq!(libc::WEXITSTATUS(status), 0, "bit mask of checks that failed");
    assert!(!dir.path().join("written").exists());
}
