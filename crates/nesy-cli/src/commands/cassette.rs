//! `nesy cassette`: look after the VLM cassettes that let runs replay offline.
//!
//! - `inspect` lists a cassette's calls, tokens and models;
//! - `prune` drops the interactions a run did not use (from the usage report that run wrote
//!   with `NESY_CASSETTE_USAGE`), and optionally blobs nothing refers to any more;
//! - `verify` checks that every blob exists and matches its hash, that stored keys match
//!   their requests, and that every response decodes. Exit code 1 if anything is wrong;
//! - `replies` counts how many induction, patch and translation replies nesy's parsers read,
//!   on the first try and after a re-ask, per method of a benchmark run's cassettes;
//! - `resend` sends recorded requests again to a live server (optionally without their reply
//!   constraint) and records the answers in a new cassette: the same prompts answered again,
//!   for a paired comparison.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use nesy_vlm::cassette_tools as tools;

/// Arguments of `nesy cassette`.
#[derive(Debug, clap::Args)]
pub(crate) struct CassetteArgs {
    /// What to do with the cassette.
    #[command(subcommand)]
    pub action: CassetteAction,
}

/// The `nesy cassette` actions.
#[derive(Debug, clap::Subcommand)]
pub(crate) enum CassetteAction {
    /// List the recorded calls with their purpose, model, images, status, tokens and latency.
    Inspect {
        /// The cassette file.
        cassette: PathBuf,
        /// Print the listing as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Drop interactions that a replay run did not use.
    Prune {
        /// The cassette file.
        cassette: PathBuf,
        /// Usage report written by the run (set `NESY_CASSETTE_USAGE=FILE` when replaying).
        #[arg(long, value_name = "FILE")]
        used: PathBuf,
        /// Also delete blobs that no cassette in the same directory refers to.
        #[arg(long)]
        orphan_blobs: bool,
        /// Show what would change without writing.
        #[arg(long)]
        dry_run: bool,
        /// Print the outcome as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Count the induction, patch and translation replies nesy's parsers read, first tries and
    /// re-asks apart, grouped by cassette name (a benchmark run's `cassettes/` folder holds
    /// one per scenario and method, named after the method).
    Replies {
        /// Cassette files, or folders searched for them.
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Print the counts as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Send recorded requests again to the configured live server and record the answers in
    /// a new cassette (resumable: what it already holds is not sent again). Read the result
    /// with `nesy cassette replies`.
    Resend {
        /// Cassette files, or folders searched for them.
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// The cassette to record the answers in.
        #[arg(long, value_name = "CASSETTE")]
        out: PathBuf,
        /// Only requests of these purposes, comma-separated (e.g. `induce,patch`).
        #[arg(long, value_name = "LIST", value_delimiter = ',')]
        purposes: Vec<String>,
        /// Only the first request of each conversation (the model's first try).
        #[arg(long)]
        first_tries: bool,
        /// At most this many requests of each purpose.
        #[arg(long, value_name = "N")]
        per_purpose: Option<usize>,
        /// Send each prompt without its reply constraint (grammar or JSON schema).
        #[arg(long)]
        strip_constraints: bool,
        /// Requests in flight at once (match the server's slots).
        #[arg(long, value_name = "N", default_value_t = 1)]
        jobs: usize,
        /// VLM settings (also from the environment and `--vlm-config`).
        #[command(flatten)]
        vlm_config: Box<nesy_vlm::ConfigOverrides>,
    },
    /// Check blobs, keys and response bodies; exit 1 if anything is wrong.
    Verify {
        /// Cassette files.
        #[arg(required = true)]
        cassettes: Vec<PathBuf>,
        /// Print the problems as JSON.
        #[arg(long)]
        json: bool,
    },
}

/// Runs `nesy cassette`.
pub(crate) fn run(args: CassetteArgs) -> anyhow::Result<ExitCode> {
    match args.action {
        CassetteAction::Inspect { cassette, json } => inspect(&cassette, json),
        CassetteAction::Replies { paths, json } => replies(&paths, json),
        CassetteAction::Resend {
            paths,
            out,
            purposes,
            first_tries,
            per_purpose,
            strip_constraints,
            jobs,
            vlm_config,
        } => {
            let plan = tools::ResendPlan {
                purposes,
                first_tries_only: first_tries,
                per_purpose,
                strip_constraints,
            };
            resend(&paths, &out, &plan, jobs, &vlm_config)
        }
        CassetteAction::Prune {
            cassette,
            used,
            orphan_blobs,
            dry_run,
            json,
        } => {
            let report = tools::load_usage_report(&used).context("reading the usage report")?;
            let outcome = tools::prune(&cassette, &report, orphan_blobs, dry_run)
                .with_context(|| format!("pruning {}", cassette.display()))?;
            if json {
                outln!("{}", serde_json::to_string_pretty(&outcome)?)?;
            } else {
                let verb = if dry_run { "would drop" } else { "dropped" };
                outln!(
                    "{}: kept {}, {verb} {} interaction(s)",
                    cassette.display(),
                    outcome.kept,
                    outcome.dropped.len()
                )?;
                for index in &outcome.dropped {
                    outln!("  {verb} #{index}")?;
                }
                for blob in &outcome.removed_blobs {
                    outln!(
                        "  {} blob {}",
                        if dry_run { "would remove" } else { "removed" },
                        blob.display()
                    )?;
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        CassetteAction::Verify { cassettes, json } => {
            let mut all = Vec::new();
            for cassette in &cassettes {
                let problems =
                    tools::verify(cassette).with_context(|| format!("verifying {}", cassette.display()))?;
                all.push((cassette.clone(), problems));
            }
            let failed = all.iter().any(|(_, problems)| !problems.is_empty());
            if json {
                let value: Vec<_> = all
                    .iter()
                    .map(|(path, problems)| serde_json::json!({"cassette": path, "problems": problems}))
                    .collect();
                outln!("{}", serde_json::to_string_pretty(&value)?)?;
            } else {
                for (path, problems) in &all {
                    if problems.is_empty() {
                        outln!("{}: ok", path.display())?;
                    }
                    for problem in problems {
                        let at = problem
                            .interaction
                            .map(|i| format!(" interaction #{i}:"))
                            .unwrap_or_default();
                        outln!("{}:{at} {}", path.display(), problem.message)?;
                    }
                }
            }
            Ok(if failed {
                ExitCode::from(1)
            } else {
                ExitCode::SUCCESS
            })
        }
    }
}

fn inspect(cassette: &std::path::Path, json: bool) -> anyhow::Result<ExitCode> {
    let listing = tools::inspect(cassette).with_context(|| format!("inspecting {}", cassette.display()))?;
    if json {
        outln!("{}", serde_json::to_string_pretty(&listing)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    let meta = &listing.meta;
    outln!(
        "{}: schema {}, recorded by {} ({}), backend {}, created {}, updated {}",
        cassette.display(),
        listing.schema_version,
        meta.recorder,
        meta.model.as_deref().unwrap_or("?"),
        meta.backend.as_deref().unwrap_or("?"),
        meta.created_at,
        meta.updated_at
    )?;
    outln!(
        "{:>4}  {:<12}  {:<14}  {:<20}  {:>4}  {:>4}  {:>6}  {:<8}  {:>8}  {:>8}  {:>8}  {:>9}",
        "#",
        "key",
        "purpose",
        "model",
        "msgs",
        "imgs",
        "status",
        "finish",
        "prompt",
        "output",
        "reason",
        "ms"
    )?;
    for call in &listing.interactions {
        outln!(
            "{:>4}  {:<12}  {:<14}  {:<20}  {:>4}  {:>4}  {:>6}  {:<8}  {:>8}  {:>8}  {:>8}  {:>9.1}",
            call.index,
            call.key,
            call.purpose.as_deref().unwrap_or("-"),
            call.model.as_deref().unwrap_or("-"),
            call.messages,
            call.images,
            call.status,
            call.finish_reason
                .as_deref()
                .or(call.failure.as_deref())
                .unwrap_or("-"),
            call.prompt_tokens,
            call.completion_tokens,
            call.reasoning_tokens,
            call.latency_ms
        )?;
    }
    let models: Vec<String> = listing
        .models
        .iter()
        .map(|(model, calls)| format!("{model} ×{calls}"))
        .collect();
    outln!(
        "{} call(s); tokens: {} prompt, {} output ({} reasoning); {} distinct image(s); models: {}",
        listing.interactions.len(),
        listing.prompt_tokens,
        listing.completion_tokens,
        listing.reasoning_tokens,
        listing.distinct_images,
        models.join(", ")
    )?;
    Ok(ExitCode::SUCCESS)
}

/// The cassette files under `path` (itself, when it is a file), in name order; blob folders
/// are skipped.
fn cassette_files(path: &std::path::Path, out: &mut Vec<PathBuf>) -> anyhow::Result<()> {
    if path.is_file() {
        out.push(path.to_path_buf());
        return Ok(());
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
        .with_context(|| format!("reading {}", path.display()))?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()
        .with_context(|| format!("reading {}", path.display()))?;
    entries.sort();
    for entry in entries {
        if entry.is_dir() && entry.file_name().is_some_and(|n| n != "blobs") {
            cassette_files(&entry, out)?;
        } else if entry.extension().is_some_and(|e| e == "json") {
            out.push(entry);
        }
    }
    Ok(())
}

fn resend(
    paths: &[PathBuf],
    out: &std::path::Path,
    plan: &tools::ResendPlan,
    jobs: usize,
    overrides: &nesy_vlm::ConfigOverrides,
) -> anyhow::Result<ExitCode> {
    use futures::StreamExt as _;
    use nesy_vlm::Transport as _;
    anyhow::ensure!(jobs >= 1, "--jobs must be at least 1");
    let mut files = Vec::new();
    for path in paths {
        cassette_files(path, &mut files)?;
    }
    files.retain(|f| f != out);
    anyhow::ensure!(!files.is_empty(), "no cassette (*.json) under {paths:?}");
    let tools::ResendSelection { requests, duplicates } = tools::resend_selection(&files, plan)?;
    anyhow::ensure!(!requests.is_empty(), "no recorded request matches the selection");
    if duplicates > 0 {
        eprintln!("{duplicates} picked request(s) repeat an earlier one and are sent once");
    }
    let config = nesy_vlm::VlmConfig::resolve(overrides, &nesy_vlm::ProcessEnv)
        .context("the live server's settings")?;
    let http = nesy_vlm::VlmClient::http_transport(&config)?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let cassette = nesy_vlm::CassetteTransport::open(
        out,
        nesy_vlm::CassetteMode::NewEpisodes,
        Some(std::sync::Arc::new(http)),
        nesy_vlm::CassetteOptions {
            // The metadata says whether the resent prompts kept their constraints.
            constrain: if plan.strip_constraints {
                nesy_vlm::ConstrainMode::Off
            } else {
                config.defaults.constrain
            },
            ..nesy_vlm::CassetteOptions::recording(&config)
        },
    )?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the async runtime")?;
    let total = requests.len();
    let failures = runtime.block_on(async {
        let mut done = 0usize;
        let mut failures = Vec::new();
        let mut sends = futures::stream::iter(requests.iter().map(|r| cassette.send(r))).buffered(jobs);
        while let Some(result) = sends.next().await {
            done += 1;
            match result {
                Ok(response) if response.status == 200 => {}
                Ok(response) => failures.push(format!("request {done}: HTTP {}", response.status)),
                Err(e) => failures.push(format!("request {done}: {e}")),
            }
            eprintln!("resent {done}/{total}");
        }
        failures
    });
    nesy_vlm::Transport::finish(&cassette)?;
    outln!(
        "{}: {} request(s) answered, {} failed{}",
        out.display(),
        total - failures.len(),
        failures.len(),
        if plan.strip_constraints {
            " (sent without their constraints)"
        } else {
            ""
        }
    )?;
    for failure in &failures {
        outln!("  {failure}")?;
    }
    Ok(if failures.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn replies(paths: &[PathBuf], json: bool) -> anyhow::Result<ExitCode> {
    use nesy_reasoner::readability::Readability;
    let mut files = Vec::new();
    for path in paths {
        cassette_files(path, &mut files)?;
    }
    anyhow::ensure!(!files.is_empty(), "no cassette (*.json) under {paths:?}");
    let mut readability = Readability::default();
    for file in &files {
        let cassette =
            nesy_vlm::CassetteFile::load(file).with_context(|| format!("reading {}", file.display()))?;
        let group = file
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        readability.add_cassette(&group, &cassette);
    }
    if json {
        let rows: Vec<serde_json::Value> = readability
            .groups
            .iter()
            .map(|((group, purpose), counts)| serde_json::json!({"group": group, "purpose": purpose, "counts": counts}))
            .collect();
        outln!("{}", serde_json::to_string_pretty(&rows)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    let share = |read: u64, of: u64| {
        if of == 0 {
            "-".to_owned()
        } else {
            format!("{read}/{of} ({:.1} %)", 100.0 * read as f64 / of as f64)
        }
    };
    let width = readability
        .groups
        .keys()
        .map(|(g, _)| g.len())
        .max()
        .unwrap_or(0)
        .max(5);
    outln!(
        "{:<width$}  {:<10}  {:>7}  {:>20}  {:>20}  {:>9}  {:>11}  {:>12}  {:>9}",
        "group",
        "purpose",
        "replies",
        "first try read",
        "re-asks read",
        "cut short",
        "constrained",
        "tokens out",
        "server s"
    )?;
    let by_purpose = readability.by_purpose();
    let total = by_purpose
        .iter()
        .map(|(p, c)| (("(all)".to_owned(), p.clone()), c.clone()));
    for ((group, purpose), c) in readability.groups.clone().into_iter().chain(total) {
        outln!(
            "{:<width$}  {:<10}  {:>7}  {:>20}  {:>20}  {:>9}  {:>11}  {:>12}  {:>9.1}",
            group,
            purpose,
            c.replies,
            share(c.first_read, c.first),
            share(c.reasked_read, c.reasked),
            c.cut_short,
            c.constrained,
            c.completion_tokens,
            c.server_ms as f64 / 1000.0
        )?;
    }
    outln!("{} cassette(s)", files.len())?;
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn smoke() -> PathBuf {
        nesy_testkit::workspace_root().join("fixtures/cassettes/vlm-smoke.json")
    }

    #[test]
    fn inspect_and_verify_the_smoke_fixture() {
        let inspect = CassetteArgs {
            action: CassetteAction::Inspect {
                cassette: smoke(),
                json: false,
            },
        };
        assert_eq!(run(inspect).unwrap(), ExitCode::SUCCESS);
        let verify = CassetteArgs {
            action: CassetteAction::Verify {
                cassettes: vec![smoke()],
                json: true,
            },
        };
        assert_eq!(run(verify).unwrap(), ExitCode::SUCCESS);
    }

    #[test]
    fn verify_fails_with_exit_1_on_a_missing_blob_and_errors_on_a_missing_file() {
        let dir = tempfile::tempdir().unwrap();
        let copy = dir.path().join("smoke.json");
        std::fs::copy(smoke(), &copy).unwrap();
        let verify = CassetteArgs {
            action: CassetteAction::Verify {
                cassettes: vec![copy],
                json: false,
            },
        };
        assert_eq!(
            run(verify).unwrap(),
            ExitCode::from(1),
            "no blobs beside the copy"
        );
        let missing = CassetteArgs {
            action: CassetteAction::Inspect {
                cassette: dir.path().join("nope.json"),
                json: false,
            },
        };
        let err = format!("{:#}", run(missing).unwrap_err());
        assert!(err.contains("nope.json"), "{err}");
    }

    #[test]
    fn prune_keeps_what_a_run_used() {
        let dir = tempfile::tempdir().unwrap();
        let copy = dir.path().join("smoke.json");
        std::fs::copy(smoke(), &copy).unwrap();
        let report = dir.path().join("usage.json");
        std::fs::write(
            &report,
            r#"{"schema_version": 1, "cassette": "smoke.json", "used": [], "unused": []}"#,
        )
        .unwrap();
        let prune = |dry_run| CassetteArgs {
            action: CassetteAction::Prune {
                cassette: copy.clone(),
                used: report.clone(),
                orphan_blobs: false,
                dry_run,
                json: false,
            },
        };
        assert_eq!(run(prune(true)).unwrap(), ExitCode::SUCCESS);
        assert_eq!(tools::inspect(&copy).unwrap().interactions.len(), 1);
        assert_eq!(run(prune(false)).unwrap(), ExitCode::SUCCESS);
        assert_eq!(tools::inspect(&copy).unwrap().interactions.len(), 0);
    }
}
