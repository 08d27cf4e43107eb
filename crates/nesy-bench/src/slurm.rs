//! Job-array files for Slurm: one array task per shard, each running `nesy bench run` on its
//! shard of the same run directory, and a merge job to run after them.

use std::fmt::Write as _;
use std::path::Path;

/// What the array needs.
#[derive(Debug, Clone)]
pub struct SlurmJob<'a> {
    /// The `nesy` binary (an absolute path: array tasks start elsewhere).
    pub nesy: &'a Path,
    /// The run directory (on a file system every node sees).
    pub run: &'a Path,
    /// The arguments of `nesy bench run` besides the run directory and the shard.
    pub run_args: &'a [String],
    /// Array tasks (shards).
    pub shards: usize,
    /// Cores per task.
    pub cpus: usize,
    /// Memory per task, e.g. `8G`.
    pub mem: &'a str,
    /// Time limit per task, e.g. `04:00:00`.
    pub time: &'a str,
    /// Partition, if any.
    pub partition: Option<&'a str>,
}

fn quote(s: &str) -> String {
    if s.chars()
        .all(|c| c.is_ascii_alphanumeric() || "/._-+=:,".contains(c))
    {
        s.to_owned()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// The array script (`run.sbatch`).
pub fn array_script(job: &SlurmJob) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "#!/bin/bash");
    let _ = writeln!(
        s,
        "# nesy bench: one array task per shard of {}",
        job.run.display()
    );
    let _ = writeln!(s, "#SBATCH --job-name=nesy-bench");
    let _ = writeln!(s, "#SBATCH --array=0-{}", job.shards.saturating_sub(1));
    let _ = writeln!(s, "#SBATCH --cpus-per-task={}", job.cpus);
    let _ = writeln!(s, "#SBATCH --mem={}", job.mem);
    let _ = writeln!(s, "#SBATCH --time={}", job.time);
    if let Some(p) = job.partition {
        let _ = writeln!(s, "#SBATCH --partition={p}");
    }
    let _ = writeln!(s, "#SBATCH --output={}/slurm/%A_%a.out", job.run.display());
    let _ = writeln!(s, "set -euo pipefail");
    let args: Vec<String> = job.run_args.iter().map(|a| quote(a)).collect();
    let _ = writeln!(
        s,
        "exec {} bench run {} {} --shard \"${{SLURM_ARRAY_TASK_ID}}/{}\" --jobs {}",
        quote(&job.nesy.display().to_string()),
        quote(&job.run.display().to_string()),
        args.join(" "),
        job.shards,
        job.cpus
    );
    s
}

/// The merge script (`merge.sbatch`), to submit with `--dependency=afterok:<array job id>`.
pub fn merge_script(job: &SlurmJob) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "#!/bin/bash");
    let _ = writeln!(s, "#SBATCH --job-name=nesy-bench-merge");
    let _ = writeln!(s, "#SBATCH --cpus-per-task=1");
    let _ = writeln!(s, "#SBATCH --time=00:30:00");
    if let Some(p) = job.partition {
        let _ = writeln!(s, "#SBATCH --partition={p}");
    }
    let _ = writeln!(s, "#SBATCH --output={}/slurm/merge_%j.out", job.run.display());
    let _ = writeln!(s, "set -euo pipefail");
    let _ = writeln!(
        s,
        "exec {} bench merge {}",
        quote(&job.nesy.display().to_string()),
        quote(&job.run.display().to_string())
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_array_runs_one_shard_per_task() {
        let args = vec![
            "--methods".to_owned(),
            "nesycr,imitation".to_owned(),
            "--vlm".to_owned(),
            "oracle".to_owned(),
        ];
        let job = SlurmJob {
            nesy: Path::new("/opt/nesy/bin/nesy"),
            run: Path::new("/shared/runs/r1"),
            run_args: &args,
            shards: 4,
            cpus: 2,
            mem: "8G",
            time: "02:00:00",
            partition: None,
        };
        let s = array_script(&job);
        assert!(s.contains("#SBATCH --array=0-3"), "{s}");
        assert!(s.contains("--shard \"${SLURM_ARRAY_TASK_ID}/4\""), "{s}");
        assert!(
            s.contains("bench run /shared/runs/r1 --methods nesycr,imitation --vlm oracle"),
            "{s}"
        );
        assert!(merge_script(&job).contains("bench merge /shared/runs/r1"));
    }
}
