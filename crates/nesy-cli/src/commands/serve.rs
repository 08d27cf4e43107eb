//! `nesy serve`: the run directories under one folder, and their HTML reports, in a browser.
//! Read-only, bound to the loopback address unless told otherwise; nothing outside the
//! folder is served.

use std::net::IpAddr;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use clap::Args;

/// Arguments of `nesy serve`.
#[derive(Debug, Args)]
pub(crate) struct ServeArgs {
    /// The folder of runs to serve (for example `runs/`).
    pub(crate) runs_dir: PathBuf,
    /// Address to listen on. The default, 127.0.0.1, is reachable only from this machine
    /// (forward a port with `ssh -L` to look from elsewhere); anything else exposes the runs
    /// to the network.
    #[arg(long, default_value = "127.0.0.1")]
    pub(crate) bind: IpAddr,
    /// Port to listen on (0: any free port, printed at start).
    #[arg(long, default_value_t = 8017)]
    pub(crate) port: u16,
}

/// Runs `nesy serve` until interrupted.
pub(crate) fn run(args: ServeArgs) -> anyhow::Result<ExitCode> {
    let folder = nesy_view::Folder::open(&args.runs_dir)?;
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the async runtime")?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind((args.bind, args.port))
            .await
            .with_context(|| format!("listening on {}:{}", args.bind, args.port))?;
        let address = listener.local_addr().context("reading the bound address")?;
        outln!(
            "nesy serve: {} at http://{address}/ (read-only; Ctrl-C stops it)",
            folder.root().display()
        )?;
        if !args.bind.is_loopback() {
            eprintln!(
                "warning: listening on {}, which other machines may reach; the runs are served without authentication",
                args.bind
            );
        }
        tokio::select! {
            served = nesy_view::serve(listener, folder) => served.context("serving")?,
            _ = tokio::signal::ctrl_c() => {}
        }
        Ok(ExitCode::SUCCESS)
    })
}
