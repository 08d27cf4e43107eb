//! The `nesy` binary: a thin shell over [`nesy_cli`].

fn main() -> std::process::ExitCode {
    nesy_cli::main()
}
