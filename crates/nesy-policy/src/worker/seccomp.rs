//! A seccomp-BPF filter for the worker (x86-64 only): after the interpreter is up, the
//! process may not start programs, fork, create sockets, trace processes, change the file
//! system, or open files for writing. Refused calls fail with `EPERM` (threads of its own
//! still start: `clone` with `CLONE_THREAD` is allowed, `clone3` reports `ENOSYS` so the C
//! library falls back to `clone`).

use std::io;

/// BPF opcodes, return values and `seccomp_data` offsets the filter uses.
#[cfg(target_arch = "x86_64")]
const LD_W_ABS: u16 = 0x20;
#[cfg(target_arch = "x86_64")]
const JEQ_K: u16 = 0x15;
#[cfg(target_arch = "x86_64")]
const JSET_K: u16 = 0x45;
#[cfg(target_arch = "x86_64")]
const RET_K: u16 = 0x06;
#[cfg(target_arch = "x86_64")]
const AUDIT_ARCH_X86_64: u32 = 0xC000_003E;
#[cfg(target_arch = "x86_64")]
const RET_ALLOW: u32 = 0x7fff_0000;
#[cfg(target_arch = "x86_64")]
const RET_ERRNO: u32 = 0x0005_0000;
#[cfg(target_arch = "x86_64")]
const RET_KILL_PROCESS: u32 = 0x8000_0000;
#[cfg(target_arch = "x86_64")]
const OFFSET_NR: u32 = 0;
#[cfg(target_arch = "x86_64")]
const OFFSET_ARCH: u32 = 4;
#[cfg(target_arch = "x86_64")]
const fn offset_arg(i: u32) -> u32 {
    16 + 8 * i
}

/// The system calls the worker may never make.
#[cfg(target_arch = "x86_64")]
const DENIED: &[i64] = &[
    libc::SYS_execve,
    libc::SYS_execveat,
    libc::SYS_fork,
    libc::SYS_vfork,
    libc::SYS_socket,
    libc::SYS_socketpair,
    libc::SYS_connect,
    libc::SYS_bind,
    libc::SYS_listen,
    libc::SYS_accept,
    libc::SYS_accept4,
    libc::SYS_ptrace,
    libc::SYS_process_vm_readv,
    libc::SYS_process_vm_writev,
    libc::SYS_creat,
    libc::SYS_openat2,
    libc::SYS_mkdir,
    libc::SYS_mkdirat,
    libc::SYS_rmdir,
    libc::SYS_unlink,
    libc::SYS_unlinkat,
    libc::SYS_rename,
    libc::SYS_renameat,
    libc::SYS_renameat2,
    libc::SYS_link,
    libc::SYS_linkat,
    libc::SYS_symlink,
    libc::SYS_symlinkat,
    libc::SYS_chmod,
    libc::SYS_fchmodat,
    libc::SYS_chown,
    libc::SYS_lchown,
    libc::SYS_fchownat,
    libc::SYS_truncate,
    libc::SYS_mknod,
    libc::SYS_mknodat,
    libc::SYS_mount,
    libc::SYS_umount2,
    libc::SYS_chroot,
    libc::SYS_pivot_root,
    libc::SYS_unshare,
    libc::SYS_setns,
    libc::SYS_bpf,
    libc::SYS_perf_event_open,
    libc::SYS_userfaultfd,
    libc::SYS_io_uring_setup,
    libc::SYS_keyctl,
    libc::SYS_add_key,
    libc::SYS_request_key,
    libc::SYS_kexec_load,
    libc::SYS_init_module,
    libc::SYS_finit_module,
    libc::SYS_memfd_create,
];

/// The filter program. Layout: [arch check][nr load][denied...][clone3][clone][open][openat]
/// [allow][deny][enosys][check clone: 4][check open: 4][check openat: 4] (BPF jumps only go
/// forward, so each check ends in its own returns).
#[cfg(target_arch = "x86_64")]
fn filter_program() -> Vec<libc::sock_filter> {
    use libc::sock_filter;
    let denied = DENIED;
    let write_flags = (libc::O_WRONLY | libc::O_RDWR | libc::O_CREAT | libc::O_TRUNC | libc::O_APPEND) as u32;

    let stmt = |code: u16, k: u32| sock_filter {
        code,
        jt: 0,
        jf: 0,
        k,
    };
    let jump = |code: u16, k: u32, jt: u8, jf: u8| sock_filter { code, jt, jf, k };

    let mut prog: Vec<sock_filter> = vec![
        stmt(LD_W_ABS, OFFSET_ARCH),
        jump(JEQ_K, AUDIT_ARCH_X86_64, 1, 0),
        stmt(RET_K, RET_KILL_PROCESS),
        stmt(LD_W_ABS, OFFSET_NR),
    ];
    let dispatch_start = prog.len();
    let dispatch_len = denied.len() + 4;
    let allow = dispatch_start + dispatch_len;
    let deny = allow + 1;
    let enosys = allow + 2;
    let check_clone = allow + 3;
    let check_open = allow + 7;
    let check_openat = allow + 11;
    let rel = |from: usize, to: usize| -> u8 { u8::try_from(to - from - 1).expect("filter jump too long") };
    for &nr in denied {
        let here = prog.len();
        prog.push(jump(JEQ_K, nr as u32, rel(here, deny), 0));
    }
    for (nr, target) in [
        (libc::SYS_clone3, enosys),
        (libc::SYS_clone, check_clone),
        (libc::SYS_open, check_open),
        (libc::SYS_openat, check_openat),
    ] {
        let here = prog.len();
        prog.push(jump(JEQ_K, nr as u32, rel(here, target), 0));
    }
    debug_assert_eq!(prog.len(), allow);
    prog.push(stmt(RET_K, RET_ALLOW));
    prog.push(stmt(RET_K, RET_ERRNO | libc::EPERM as u32));
    prog.push(stmt(RET_K, RET_ERRNO | libc::ENOSYS as u32));
    // clone: allowed only for threads.
    prog.push(stmt(LD_W_ABS, offset_arg(0)));
    prog.push(jump(JSET_K, libc::CLONE_THREAD as u32, 0, 1));
    prog.push(stmt(RET_K, RET_ALLOW));
    prog.push(stmt(RET_K, RET_ERRNO | libc::EPERM as u32));
    // open(path, flags) and openat(dirfd, path, flags): no writing, creating or truncating.
    for flags_arg in [1, 2] {
        prog.push(stmt(LD_W_ABS, offset_arg(flags_arg)));
        prog.push(jump(JSET_K, write_flags, 1, 0));
        prog.push(stmt(RET_K, RET_ALLOW));
        prog.push(stmt(RET_K, RET_ERRNO | libc::EPERM as u32));
    }
    debug_assert_eq!(prog.len(), check_openat + 4);
    prog
}

/// Installs the filter on every thread of the process (and sets no-new-privs, which an
/// unprivileged process needs for that).
#[cfg(target_arch = "x86_64")]
pub fn install() -> io::Result<()> {
    let mut prog = filter_program();
    // Unprivileged processes may only install filters with no-new-privs set.
    // SAFETY: prctl with integer arguments.
    if unsafe { libc::prctl(libc::PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) } != 0 {
        return Err(io::Error::last_os_error());
    }
    let fprog = libc::sock_fprog {
        len: prog.len() as u16,
        filter: prog.as_mut_ptr(),
    };
    const SECCOMP_SET_MODE_FILTER: libc::c_long = 1;
    const SECCOMP_FILTER_FLAG_TSYNC: libc::c_long = 1;
    // SAFETY: the program outlives the syscall, which copies it.
    let rc = unsafe {
        libc::syscall(
            libc::SYS_seccomp,
            SECCOMP_SET_MODE_FILTER,
            SECCOMP_FILTER_FLAG_TSYNC,
            &fprog,
        )
    };
    if rc != 0 {
        return Err(io::Error::last_os_error());
    }
    Ok(())
}

/// No filter on other architectures (documented limitation).
#[cfg(not(target_arch = "x86_64"))]
pub fn install() -> io::Result<()> {
    Ok(())
}
