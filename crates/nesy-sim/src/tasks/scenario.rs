//! The benchmark's scenario suite (`docs/benchmark.md` §6, paper Table 6): five domain factors × three
//! complexities, 220 source/target configurations, each evaluated with two seeds = 440
//! scenarios.
//!
//! - Factors: `obst` (source clean → target obstructed), `affo` (source obstructed →
//!   target clean), `grip` (finger source → vacuum target), `vacu` (vacuum source → finger
//!   target), `comb` (obstruction changes both ways, and sometimes an embodiment change).
//! - Complexities: low = 2 subtasks at multi level 0, medium = 3 at multi 1, high = all 4 at
//!   multi 2.
//! - Counts per factor: 15/15/10 configurations (low/medium/high), 20/20/20 for `comb`.
//!
//! Configurations come from nesy's own seeded streams (`world::rng::Stream`, internal); they are
//! written as 15 JSON files ([`ConfigFile`], one per factor × complexity) by
//! `nesy scenarios generate`. A scenario is a configuration plus a seed: seed `s` lays each
//! subtask out with variant `variant + s × SEED_STRIDE` and the composite offsets with
//! episode `episode_id + s × SEED_STRIDE`, so the two seeds give two different scenes of the
//! same configuration, and source and target always share layouts.
//!
//! The **complexity-gap suite** ([`generate_gap_suite`], Figure 4(b)) is auxiliary and not
//! part of the 440: with the Obstruction factor fixed, each configuration demonstrates one
//! subtask and deploys a target with 0–3 more subtasks of other kinds, every target subtask
//! obstructed. The files are `gap_obst_plus<k>.json` and the ids
//! `gap_obst_plus<k>_<NN>_s<seed>`. The demonstrated subtask keeps its kind and variant, so
//! its objects are the same; it sits at the lone-subtask offset in the demonstration and at
//! its composite slot in the target.

use std::path::Path;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

pub(crate) use nesy_core::benchmark::{Complexity, Factor};

use crate::api::Embodiment;
use crate::tasks::{GeneratedTask, SubtaskConfig, SubtaskKind, TaskConfig, TaskError};
use crate::world::rng::Stream;

/// Version of the configuration file format.
pub const CONFIG_SCHEMA_VERSION: u32 = 1;
/// The seeds every configuration is evaluated with.
pub const SEEDS: [u64; 2] = [0, 1];
/// Offset between the variants (and episodes) of consecutive seeds.
pub const SEED_STRIDE: u64 = 1000;
/// The domain factor the complexity-gap suite holds fixed (the paper's Figure 4(b) fixes
/// Obstruction).
pub const GAP_FACTOR: Factor = Factor::Obst;
/// The added-subtask counts of the complexity-gap suite: the target has this many subtasks
/// beyond the demonstration's one.
pub const GAP_ADDED: [u8; 4] = [0, 1, 2, 3];
/// Configurations per added-subtask count in the complexity-gap suite.
pub const GAP_CONFIGURATIONS: usize = 10;
/// Configurations of a real-world task's family (each evaluated with every seed of [`SEEDS`]).
pub const FAMILY_CONFIGURATIONS: usize = 10;

/// A family of scenarios for one of the paper's real-world tasks (auxiliary, not part of
/// the 440): seeded scene pairs in the demonstrator's and the deployment's settings as the
/// paper describes each. The file is `family_<name>.json` and the ids
/// `family_<name>_<NN>_s<seed>`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Family {
    /// Table 2: cubes sorted into two cabinets' drawers, demonstrated with the cabinets side
    /// by side and deployed with them at right angles (one bottom drawer cannot open while
    /// the other stands open) and the cubes stacked (`sort_into_drawers`).
    Drawers,
    /// Figures 1 and 5: a magnetic hook, screws and cubes put in a drawer, demonstrated with
    /// everything on the table and the screws on the hook's magnet, deployed with the hook
    /// already in the open drawer under a cube and the screws scattered over the table
    /// (`stow_tools`).
    Hook,
}

impl Family {
    /// Every family.
    pub const ALL: [Family; 2] = [Family::Drawers, Family::Hook];

    /// The name in file names, ids and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Family::Drawers => "drawers",
            Family::Hook => "hook",
        }
    }

    /// The family called `name`.
    pub fn from_name(name: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.as_str() == name)
    }

    /// The subtask its scenes are made of.
    pub fn subtask(self) -> SubtaskKind {
        match self {
            Family::Drawers => SubtaskKind::SortIntoDrawers,
            Family::Hook => SubtaskKind::StowTools,
        }
    }

    /// The vocabulary its tasks are stated in: the benchmark's fifteen predicates and the
    /// relations its scenes need (`Blocks` for the drawers; `Finegrained`, `Gathered` and
    /// `OnMagnet` for the hook), from `assets/vocabulary/`.
    pub fn vocabulary(self) -> Result<nesy_core::Vocabulary, nesy_core::VocabularyFileError> {
        let text = match self {
            Family::Drawers => include_str!("../../../../assets/vocabulary/blocking-drawers.toml"),
            Family::Hook => include_str!("../../../../assets/vocabulary/hook-and-screws.toml"),
        };
        nesy_core::parse_vocabulary_file(text)
    }

    /// Its file's name: `family_<name>.json`.
    pub fn file_name(self) -> String {
        format!("family_{}.json", self.as_str())
    }
}

impl std::fmt::Display for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The id of a real-world task's scenario.
pub fn family_scenario_id(family: Family, episode_id: u64, seed: u64) -> String {
    format!("family_{}_{episode_id:02}_s{seed}", family.as_str())
}

/// Generates a real-world task's family: [`FAMILY_CONFIGURATIONS`] configurations, each
/// demonstrated at obstruction level 0 and deployed at level 2 of the family's subtask by
/// the finger robot, with the object count cycling through the multi levels. Filed under
/// the Obstruction factor (the deployment adds a physical constraint), low complexity.
pub fn generate_family_file(family: Family) -> ConfigFile {
    let tag = format!("scenarios/family/{}", family.as_str());
    let episodes = (0..FAMILY_CONFIGURATIONS)
        .map(|i| {
            let mut rng = Stream::new(&tag, i as u64);
            let variant = rng.index(SEED_STRIDE as usize) as u64;
            let side = |obst_level: u8| {
                vec![SubtaskConfig {
                    kind: family.subtask(),
                    variant,
                    obst_level,
                    multi_level: (i % 3) as u8,
                }]
            };
            EpisodeConfig {
                episode_id: i as u64,
                source_subtasks: side(0),
                target_subtasks: side(2),
                source_embodiment: Embodiment::Finger,
                target_embodiment: Embodiment::Finger,
                embodiment_in_state: false,
            }
        })
        .collect();
    ConfigFile {
        schema_version: CONFIG_SCHEMA_VERSION,
        factor: Factor::Obst,
        complexity: Complexity::Low,
        seeds: SEEDS.to_vec(),
        added_subtasks: None,
        family: Some(family),
        episodes,
    }
}

/// One source/target configuration (the authors' episode).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EpisodeConfig {
    /// Episode number within its file, from 0.
    pub episode_id: u64,
    /// The demo's subtasks, in instruction order.
    pub source_subtasks: Vec<SubtaskConfig>,
    /// The deployment's subtasks: the same kinds and variants, other obstruction levels, and
    /// in the complexity-gap suite the file's `added_subtasks` more after them.
    pub target_subtasks: Vec<SubtaskConfig>,
    /// The demonstrating robot.
    pub source_embodiment: Embodiment,
    /// The deploying robot.
    pub target_embodiment: Embodiment,
    /// States name the end effector (`(FingerGripper)` / `(VacuumSuction)`): the authors'
    /// `ee_set`, on for `grip`, `vacu` and `comb`.
    pub embodiment_in_state: bool,
}

/// One configuration file: all episodes of a factor at a complexity.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConfigFile {
    /// Format version; must be 1.
    pub schema_version: u32,
    /// The domain factor.
    pub factor: Factor,
    /// The complexity.
    pub complexity: Complexity,
    /// Seeds each episode is evaluated with.
    pub seeds: Vec<u64>,
    /// In a complexity-gap file, the subtasks each target has beyond its demonstration's
    /// (0–3); absent in the files of the 440 suite.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub added_subtasks: Option<u8>,
    /// In a real-world task's file, the task ([`Family`]); absent in the files of the 440
    /// suite.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub family: Option<Family>,
    /// The episodes.
    pub episodes: Vec<EpisodeConfig>,
}

/// Why a configuration file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// The JSON does not parse or does not match the format.
    #[error("{path}: at {field}: {message}")]
    Json {
        /// The file.
        path: String,
        /// JSON path of the offending value.
        field: String,
        /// What serde expected (with line and column).
        message: String,
    },
    /// A value parsed but is not acceptable.
    #[error("{path}: at {field}: expected {expected}, found {found}")]
    Invalid {
        /// The file.
        path: String,
        /// JSON path of the offending value.
        field: String,
        /// What would have been acceptable.
        expected: String,
        /// What was there.
        found: String,
    },
    /// No scenario has this id.
    #[error(
        "unknown scenario {id:?}: expected <factor>_<complexity>_<NN>_s<seed> (e.g. obst_low_00_s0), gap_obst_plus<k>_<NN>_s<seed> or family_<name>_<NN>_s<seed> (see `nesy scenarios list --ids`)"
    )]
    UnknownScenario {
        /// The id asked for.
        id: String,
    },
    /// A side's task does not generate.
    #[error("scenario {id}, {side}: {source}")]
    Task {
        /// The scenario.
        id: String,
        /// `source` or `target`.
        side: Side,
        /// Why.
        source: TaskError,
    },
}

/// Which side of a scenario.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// The demonstration.
    Source,
    /// The deployment.
    Target,
}

impl Side {
    /// `source` or `target`.
    pub fn as_str(self) -> &'static str {
        match self {
            Side::Source => "source",
            Side::Target => "target",
        }
    }
}

impl std::fmt::Display for Side {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The file name of a configuration file: `<factor>_<complexity>.json`.
pub fn config_file_name(factor: Factor, complexity: Complexity) -> String {
    format!("{}_{}.json", factor.as_str(), complexity.as_str())
}

/// The file name of a complexity-gap file: `gap_<factor>_plus<k>.json`.
pub fn gap_file_name(factor: Factor, added: u8) -> String {
    format!("gap_{}_plus{added}.json", factor.as_str())
}

/// Ordered obstruction changes `comb` draws from, per subtask (source → target).
const COMB_CHANGES: [(u8, u8); 6] = [(0, 1), (0, 2), (1, 0), (2, 0), (1, 2), (2, 1)];

/// `comb` end-effector mixes per complexity (`docs/benchmark.md` §6): episodes with a finger source, with a
/// vacuum source, and with no embodiment change.
fn comb_embodiments(complexity: Complexity) -> (usize, usize, usize) {
    match complexity {
        Complexity::Low => (4, 3, 13),
        Complexity::Medium => (4, 4, 12),
        Complexity::High => (5, 6, 9),
    }
}

/// Generates one configuration file.
pub fn generate_file(factor: Factor, complexity: Complexity) -> ConfigFile {
    let count = factor.configurations(complexity);
    let tag = format!("scenarios/{}/{}", factor.as_str(), complexity.as_str());
    // Which comb episodes change the embodiment, and which way.
    let mut comb_ee: Vec<Option<Embodiment>> = Vec::new();
    if factor == Factor::Comb {
        let (finger, vacuum, none) = comb_embodiments(complexity);
        comb_ee.extend(std::iter::repeat_n(Some(Embodiment::Finger), finger));
        comb_ee.extend(std::iter::repeat_n(Some(Embodiment::Vacuum), vacuum));
        comb_ee.extend(std::iter::repeat_n(None, none));
        Stream::new(&format!("{tag}/embodiments"), 0).shuffle(&mut comb_ee);
    }
    let episodes = (0..count)
        .map(|i| {
            let mut rng = Stream::new(&tag, i as u64);
            let mut kinds = SubtaskKind::ALL.to_vec();
            rng.shuffle(&mut kinds);
            kinds.truncate(complexity.subtasks());
            let multi = complexity.multi_level();
            let mut pairs: Vec<(u8, u8)> = kinds
                .iter()
                .map(|_| match factor {
                    Factor::Obst => (0, 1 + rng.index(2) as u8),
                    Factor::Affo => (1 + rng.index(2) as u8, 0),
                    Factor::Grip | Factor::Vacu => (0, 0),
                    Factor::Comb => {
                        if rng.index(3) == 0 {
                            let same = rng.index(3) as u8;
                            (same, same)
                        } else {
                            COMB_CHANGES[rng.index(COMB_CHANGES.len())]
                        }
                    }
                })
                .collect();
            if factor == Factor::Comb && pairs.iter().all(|(s, t)| s == t) {
                let k = rng.index(pairs.len());
                pairs[k] = COMB_CHANGES[rng.index(COMB_CHANGES.len())];
            }
            let variants: Vec<u64> = kinds
                .iter()
                .map(|_| rng.index(SEED_STRIDE as usize) as u64)
                .collect();
            let side = |target: bool| -> Vec<SubtaskConfig> {
                kinds
                    .iter()
                    .zip(&pairs)
                    .zip(&variants)
                    .map(|((&kind, &(s, t)), &variant)| SubtaskConfig {
                        kind,
                        variant,
                        obst_level: if target { t } else { s },
                        multi_level: multi,
                    })
                    .collect()
            };
            let (source_embodiment, target_embodiment) = match factor {
                Factor::Grip => (Embodiment::Finger, Embodiment::Vacuum),
                Factor::Vacu => (Embodiment::Vacuum, Embodiment::Finger),
                Factor::Comb => match comb_ee[i] {
                    Some(Embodiment::Finger) => (Embodiment::Finger, Embodiment::Vacuum),
                    Some(Embodiment::Vacuum) => (Embodiment::Vacuum, Embodiment::Finger),
                    None => (Embodiment::Finger, Embodiment::Finger),
                },
                Factor::Obst | Factor::Affo => (Embodiment::Finger, Embodiment::Finger),
            };
            EpisodeConfig {
                episode_id: i as u64,
                source_subtasks: side(false),
                target_subtasks: side(true),
                source_embodiment,
                target_embodiment,
                embodiment_in_state: factor.names_embodiment(),
            }
        })
        .collect();
    ConfigFile {
        schema_version: CONFIG_SCHEMA_VERSION,
        factor,
        complexity,
        seeds: SEEDS.to_vec(),
        added_subtasks: None,
        family: None,
        episodes,
    }
}

/// Generates the complexity-gap file with `added` subtasks beyond the demonstration's one
/// (at most 3: a task has at most four subtasks, each kind once).
///
/// Configuration `i` draws its kind order, variants and target obstruction levels from one
/// stream that does not depend on `added`, so the files differ only in how many of the
/// drawn subtasks the target keeps: configuration `i` demonstrates the same subtask in
/// every file, and the gap grows by appending subtasks.
pub fn generate_gap_file(added: u8) -> ConfigFile {
    let tag = format!("scenarios/gap/{}", GAP_FACTOR.as_str());
    let episodes = (0..GAP_CONFIGURATIONS)
        .map(|i| {
            let mut rng = Stream::new(&tag, i as u64);
            let mut kinds = SubtaskKind::ALL.to_vec();
            rng.shuffle(&mut kinds);
            let drawn: Vec<(SubtaskKind, u64, u8)> = kinds
                .into_iter()
                .map(|kind| {
                    (
                        kind,
                        rng.index(SEED_STRIDE as usize) as u64,
                        1 + rng.index(2) as u8,
                    )
                })
                .collect();
            let subtask = |&(kind, variant, obst_level): &(SubtaskKind, u64, u8)| SubtaskConfig {
                kind,
                variant,
                obst_level,
                multi_level: 0,
            };
            let target_subtasks: Vec<SubtaskConfig> =
                drawn.iter().take(1 + usize::from(added)).map(subtask).collect();
            // The demonstration shows the first subtask unobstructed (Obstruction: a clean
            // source, an obstructed target).
            let source_subtasks = vec![SubtaskConfig {
                obst_level: 0,
                ..target_subtasks[0]
            }];
            EpisodeConfig {
                episode_id: i as u64,
                source_subtasks,
                target_subtasks,
                source_embodiment: Embodiment::Finger,
                target_embodiment: Embodiment::Finger,
                embodiment_in_state: GAP_FACTOR.names_embodiment(),
            }
        })
        .collect();
    ConfigFile {
        schema_version: CONFIG_SCHEMA_VERSION,
        factor: GAP_FACTOR,
        complexity: Complexity::Low,
        seeds: SEEDS.to_vec(),
        added_subtasks: Some(added),
        family: None,
        episodes,
    }
}

/// Generates the four complexity-gap files (0 to 3 added subtasks): 10 configurations × 2
/// seeds each, 80 scenarios, none of them among the 440.
pub fn generate_gap_suite() -> Vec<ConfigFile> {
    GAP_ADDED.iter().map(|&k| generate_gap_file(k)).collect()
}

/// Generates all 15 configuration files, factor-major.
pub fn generate_suite() -> Vec<ConfigFile> {
    Factor::ALL
        .iter()
        .flat_map(|&f| Complexity::ALL.iter().map(move |&c| generate_file(f, c)))
        .collect()
}

/// JSON Schema of a configuration file.
pub fn config_schema() -> String {
    let mut text = serde_json::to_string_pretty(&schemars::schema_for!(ConfigFile)).unwrap_or_default();
    text.push('\n');
    text
}

impl ConfigFile {
    /// The file's name in a suite folder: [`config_file_name`], or [`gap_file_name`] for a
    /// complexity-gap file.
    pub fn file_name(&self) -> String {
        match (self.family, self.added_subtasks) {
            (Some(family), _) => family.file_name(),
            (None, None) => config_file_name(self.factor, self.complexity),
            (None, Some(added)) => gap_file_name(self.factor, added),
        }
    }

    /// Pretty JSON with a trailing newline.
    pub fn to_json_pretty(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).unwrap_or_default();
        text.push('\n');
        text
    }

    /// Parses and validates a configuration file; `origin` names it in errors.
    pub fn from_json_str(text: &str, origin: &str) -> Result<ConfigFile, ScenarioError> {
        let de = &mut serde_json::Deserializer::from_str(text);
        let file: ConfigFile = serde_path_to_error::deserialize(de).map_err(|e| ScenarioError::Json {
            path: origin.to_owned(),
            field: e.path().to_string(),
            message: e.into_inner().to_string(),
        })?;
        file.validate(origin)?;
        Ok(file)
    }

    /// Reads a configuration file.
    pub fn from_file(path: &Path) -> Result<ConfigFile, ScenarioError> {
        let text =
            nesy_input::read_text(path, nesy_input::MAX_JSON_BYTES).map_err(|source| ScenarioError::Io {
                path: path.display().to_string(),
                source,
            })?;
        ConfigFile::from_json_str(&text, &path.display().to_string())
    }

    /// Checks the version, the subtask lists of every episode, and that source and target
    /// share kinds and variants (in a complexity-gap file: that the target starts with the
    /// source's subtasks, in order, and has `added_subtasks` more).
    pub fn validate(&self, origin: &str) -> Result<(), ScenarioError> {
        let invalid = |field: String, expected: &str, found: String| ScenarioError::Invalid {
            path: origin.to_owned(),
            field,
            expected: expected.to_owned(),
            found,
        };
        if self.schema_version != CONFIG_SCHEMA_VERSION {
            return Err(invalid(
                "schema_version".into(),
                "1",
                self.schema_version.to_string(),
            ));
        }
        if self.seeds.is_empty() {
            return Err(invalid("seeds".into(), "at least one seed", "[]".into()));
        }
        for (e, episode) in self.episodes.iter().enumerate() {
            for (side, list) in [
                ("source_subtasks", &episode.source_subtasks),
                ("target_subtasks", &episode.target_subtasks),
            ] {
                let task = TaskConfig {
                    subtasks: list.clone(),
                    episode: episode.episode_id,
                    embodiment: Embodiment::Finger,
                    embodiment_in_state: false,
                };
                task.validate().map_err(|err| {
                    invalid(
                        format!("episodes[{e}].{side}"),
                        "a valid subtask list",
                        err.to_string(),
                    )
                })?;
            }
            // A family's file holds its own subtask; the others, the benchmark's four.
            for (side, list) in [
                ("source_subtasks", &episode.source_subtasks),
                ("target_subtasks", &episode.target_subtasks),
            ] {
                for (k, subtask) in list.iter().enumerate() {
                    let fits = match self.family {
                        Some(family) => subtask.kind == family.subtask(),
                        None => SubtaskKind::ALL.contains(&subtask.kind),
                    };
                    if !fits {
                        let expected = match self.family {
                            Some(family) => format!("{} (the {family} family's subtask)", family.subtask()),
                            None => "one of the benchmark's four subtasks".to_owned(),
                        };
                        return Err(invalid(
                            format!("episodes[{e}].{side}[{k}].kind"),
                            &expected,
                            subtask.kind.to_string(),
                        ));
                    }
                }
            }
            let key = |s: &SubtaskConfig| (s.kind, s.variant);
            let mut a: Vec<_> = episode.source_subtasks.iter().map(key).collect();
            let mut b: Vec<_> = episode.target_subtasks.iter().map(key).collect();
            if let Some(added) = self.added_subtasks {
                let wanted = a.len() + usize::from(added);
                if b.len() != wanted || b[..a.len()] != a[..] {
                    return Err(invalid(
                        format!("episodes[{e}].target_subtasks"),
                        &format!(
                            "the source's {} subtask(s) in order, then {} more (added_subtasks)",
                            a.len(),
                            added
                        ),
                        format!("{b:?} (source {a:?})"),
                    ));
                }
                continue;
            }
            a.sort();
            b.sort();
            if a != b {
                return Err(invalid(
                    format!("episodes[{e}].target_subtasks"),
                    "the source's subtask kinds and variants",
                    format!("{b:?} (source {a:?})"),
                ));
            }
        }
        Ok(())
    }
}

/// Writes the 15 files into `dir`; returns their paths.
pub fn write_suite(files: &[ConfigFile], dir: &Path) -> Result<Vec<std::path::PathBuf>, ScenarioError> {
    std::fs::create_dir_all(dir).map_err(|source| ScenarioError::Io {
        path: dir.display().to_string(),
        source,
    })?;
    files
        .iter()
        .map(|file| {
            let path = dir.join(file.file_name());
            std::fs::write(&path, file.to_json_pretty()).map_err(|source| ScenarioError::Io {
                path: path.display().to_string(),
                source,
            })?;
            Ok(path)
        })
        .collect()
}

/// Reads every `<factor>_<complexity>.json`, `gap_<factor>_plus<k>.json` and
/// `family_<name>.json` present in `dir` (at least one must exist).
pub fn read_suite(dir: &Path) -> Result<Vec<ConfigFile>, ScenarioError> {
    let mut files = Vec::new();
    for factor in Factor::ALL {
        for complexity in Complexity::ALL {
            let path = dir.join(config_file_name(factor, complexity));
            if !path.exists() {
                continue;
            }
            let file = ConfigFile::from_file(&path)?;
            if (file.factor, file.complexity, file.added_subtasks) != (factor, complexity, None) {
                return Err(ScenarioError::Invalid {
                    path: path.display().to_string(),
                    field: "factor/complexity".into(),
                    expected: format!("{factor}/{complexity} (from the file name)"),
                    found: format!("{}/{}", file.factor, file.complexity),
                });
            }
            files.push(file);
        }
    }
    for added in GAP_ADDED {
        let path = dir.join(gap_file_name(GAP_FACTOR, added));
        if !path.exists() {
            continue;
        }
        let file = ConfigFile::from_file(&path)?;
        if (file.factor, file.added_subtasks) != (GAP_FACTOR, Some(added)) {
            return Err(ScenarioError::Invalid {
                path: path.display().to_string(),
                field: "factor/added_subtasks".into(),
                expected: format!("{GAP_FACTOR}/{added} (from the file name)"),
                found: format!(
                    "{}/{}",
                    file.factor,
                    file.added_subtasks.map_or("absent".to_owned(), |k| k.to_string())
                ),
            });
        }
        files.push(file);
    }
    for family in Family::ALL {
        let path = dir.join(family.file_name());
        if !path.exists() {
            continue;
        }
        let file = ConfigFile::from_file(&path)?;
        if file.family != Some(family) {
            return Err(ScenarioError::Invalid {
                path: path.display().to_string(),
                field: "family".into(),
                expected: format!("{family} (from the file name)"),
                found: file.family.map_or("absent".to_owned(), |f| f.to_string()),
            });
        }
        files.push(file);
    }
    if files.is_empty() {
        return Err(ScenarioError::Io {
            path: dir.display().to_string(),
            source: std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "no <factor>_<complexity>.json, gap_<factor>_plus<k>.json or family_<name>.json configuration files (write them with `nesy scenarios generate`)",
            ),
        });
    }
    Ok(files)
}

/// One evaluation scenario: a configuration and a seed.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// `<factor>_<complexity>_<NN>_s<seed>`, e.g. `comb_high_07_s1`, or
    /// `gap_<factor>_plus<k>_<NN>_s<seed>` in the complexity-gap suite.
    pub id: String,
    /// The domain factor.
    pub factor: Factor,
    /// The complexity (the file's). In the complexity-gap suite it is `low` for every file
    /// and stands for nothing: the id parses to the target's complexity
    /// ([`nesy_core::benchmark::parse_scenario_id`]), which sets the budget, and
    /// [`CountTable`] counts these scenarios by added subtasks instead.
    pub complexity: Complexity,
    /// Subtasks the target has beyond the demonstration's, in the complexity-gap suite
    /// (`None` in the 440).
    pub added_subtasks: Option<u8>,
    /// The real-world task whose family it belongs to (`None` in the 440).
    pub family: Option<Family>,
    /// The configuration.
    pub episode: EpisodeConfig,
    /// The seed.
    pub seed: u64,
}

/// A scenario's two scenes.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioScenes {
    /// The demonstration scene (with goals and instruction).
    pub source: GeneratedTask,
    /// The deployment scene.
    pub target: GeneratedTask,
}

impl ScenarioScenes {
    /// The target's goal label (what an adapted policy must achieve, in order).
    pub fn goal_label(&self) -> &[String] {
        &self.target.goal_label
    }
}

/// The id of a scenario.
pub fn scenario_id(factor: Factor, complexity: Complexity, episode_id: u64, seed: u64) -> String {
    format!(
        "{}_{}_{episode_id:02}_s{seed}",
        factor.as_str(),
        complexity.as_str()
    )
}

/// The id of a complexity-gap scenario.
pub fn gap_scenario_id(factor: Factor, added: u8, episode_id: u64, seed: u64) -> String {
    format!("gap_{}_plus{added}_{episode_id:02}_s{seed}", factor.as_str())
}

impl Scenario {
    /// The obstruction change from demonstration to target, Σ |target obst − source obst|
    /// over the subtasks (the domain-gap measure of Figure 4(a)); `None` for a
    /// complexity-gap scenario, whose target has subtasks the demonstration lacks.
    pub fn obstruction_change(&self) -> Option<u32> {
        if self.added_subtasks.is_some() {
            return None;
        }
        Some(
            self.episode
                .source_subtasks
                .iter()
                .zip(&self.episode.target_subtasks)
                .map(|(a, b)| u32::from(a.obst_level.abs_diff(b.obst_level)))
                .sum(),
        )
    }

    /// The task configuration of one side, with this scenario's seed applied.
    pub fn task(&self, side: Side) -> TaskConfig {
        let (subtasks, embodiment) = match side {
            Side::Source => (&self.episode.source_subtasks, self.episode.source_embodiment),
            Side::Target => (&self.episode.target_subtasks, self.episode.target_embodiment),
        };
        TaskConfig {
            subtasks: subtasks
                .iter()
                .map(|s| SubtaskConfig {
                    variant: s.variant + self.seed * SEED_STRIDE,
                    ..*s
                })
                .collect(),
            episode: self.episode.episode_id + self.seed * SEED_STRIDE,
            embodiment,
            embodiment_in_state: self.episode.embodiment_in_state,
        }
    }

    /// Generates one side's scene.
    pub fn generate(&self, side: Side) -> Result<GeneratedTask, ScenarioError> {
        self.task(side).generate().map_err(|source| ScenarioError::Task {
            id: self.id.clone(),
            side,
            source,
        })
    }

    /// Generates both scenes.
    pub fn scenes(&self) -> Result<ScenarioScenes, ScenarioError> {
        Ok(ScenarioScenes {
            source: self.generate(Side::Source)?,
            target: self.generate(Side::Target)?,
        })
    }
}

/// Every scenario of the files: configurations × seeds, in file and episode order.
pub fn scenarios(files: &[ConfigFile]) -> Vec<Scenario> {
    files
        .iter()
        .flat_map(|file| {
            file.episodes.iter().flat_map(move |episode| {
                file.seeds.iter().map(move |&seed| Scenario {
                    id: match (file.family, file.added_subtasks) {
                        (Some(family), _) => family_scenario_id(family, episode.episode_id, seed),
                        (None, Some(added)) => gap_scenario_id(file.factor, added, episode.episode_id, seed),
                        (None, None) => scenario_id(file.factor, file.complexity, episode.episode_id, seed),
                    },
                    factor: file.factor,
                    complexity: file.complexity,
                    added_subtasks: file.added_subtasks,
                    family: file.family,
                    episode: episode.clone(),
                    seed,
                })
            })
        })
        .collect()
}

/// The generated suite a scenario id belongs to: the complexity-gap suite for `gap_…`, a
/// family's file for `family_<name>_…`, else the 440.
pub fn generated_suite_of(id: &str) -> Vec<ConfigFile> {
    if id.starts_with("gap_") {
        return generate_gap_suite();
    }
    if let Some(rest) = id.strip_prefix("family_")
        && let Some(family) = Family::ALL
            .into_iter()
            .find(|f| rest.strip_prefix(f.as_str()).is_some_and(|r| r.starts_with('_')))
    {
        return vec![generate_family_file(family)];
    }
    generate_suite()
}

/// Finds a scenario by id.
pub fn find(files: &[ConfigFile], id: &str) -> Result<Scenario, ScenarioError> {
    scenarios(files)
        .into_iter()
        .find(|s| s.id == id)
        .ok_or_else(|| ScenarioError::UnknownScenario { id: id.to_owned() })
}

/// Scenario counts by factor and complexity (the paper's Table 6), and the complexity-gap
/// scenarios apart.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CountTable {
    /// `(factor, [low, medium, high])`, in [`Factor::ALL`] order, over the scenarios of the
    /// 440 only.
    pub by_factor: Vec<(Factor, [usize; 3])>,
    /// `(added subtasks, scenarios)` of the auxiliary complexity-gap suite, ascending; empty
    /// when none were counted. These are kept out of `by_factor`: their file complexity is a
    /// placeholder, not a row of Table 6.
    pub gap: Vec<(u8, usize)>,
    /// `(family, scenarios)` of the real-world tasks' families, in [`Family::ALL`] order;
    /// empty when none were counted. Kept out of `by_factor` too.
    pub families: Vec<(Family, usize)>,
}

impl CountTable {
    /// Counts the scenarios.
    pub fn of(scenarios: &[Scenario]) -> CountTable {
        let by_factor = Factor::ALL
            .iter()
            .map(|&f| {
                let mut row = [0; 3];
                for s in scenarios
                    .iter()
                    .filter(|s| s.factor == f && s.added_subtasks.is_none() && s.family.is_none())
                {
                    row[s.complexity as usize] += 1;
                }
                (f, row)
            })
            .collect();
        let mut gap = std::collections::BTreeMap::<u8, usize>::new();
        for added in scenarios.iter().filter_map(|s| s.added_subtasks) {
            *gap.entry(added).or_default() += 1;
        }
        let families = Family::ALL
            .into_iter()
            .map(|family| {
                (
                    family,
                    scenarios.iter().filter(|s| s.family == Some(family)).count(),
                )
            })
            .filter(|(_, n)| *n > 0)
            .collect();
        CountTable {
            by_factor,
            gap: gap.into_iter().collect(),
            families,
        }
    }

    /// The rows of the paper's Table 6 (factors grouped), with per-complexity counts.
    pub fn paper_rows(&self) -> Vec<(&'static str, [usize; 3])> {
        let mut rows: Vec<(&'static str, [usize; 3])> = Vec::new();
        for &(factor, counts) in &self.by_factor {
            let name = factor.group().title();
            match rows.iter_mut().find(|(n, _)| *n == name) {
                Some((_, row)) => (0..3).for_each(|i| row[i] += counts[i]),
                None => rows.push((name, counts)),
            }
        }
        rows
    }

    /// Column totals.
    pub fn totals(&self) -> [usize; 3] {
        let mut t = [0; 3];
        for (_, row) in &self.by_factor {
            (0..3).for_each(|i| t[i] += row[i]);
        }
        t
    }

    /// The table as text: one row per factor, then the paper's grouping, then totals; then,
    /// if any were counted, the complexity-gap scenarios by added subtasks, labelled as not
    /// part of the 440, and the real-world tasks' families likewise. A suite of auxiliary
    /// files only prints those parts.
    pub fn render(&self) -> String {
        let mut out = String::new();
        if self.totals().iter().sum::<usize>() > 0 || (self.gap.is_empty() && self.families.is_empty()) {
            self.render_main(&mut out);
        }
        if !self.families.is_empty() {
            if !out.is_empty() {
                out.push('\n');
            }
            out.push_str("real-world task families (auxiliary; not part of the 440)\n");
            for &(family, n) in &self.families {
                out.push_str(&format!("{:<34}{n:>7}\n", family.as_str()));
            }
        }
        if !self.gap.is_empty() {
            if !out.is_empty() {
                out.push('\n');
            }
            out.push_str("complexity-gap suite (auxiliary, Figure 4(b); not part of the 440)\n");
            out.push_str(&format!("{:<34}{:>7}\n", "added subtasks", "total"));
            for &(added, n) in &self.gap {
                out.push_str(&format!("{:<34}{n:>7}\n", format!("+{added}")));
            }
            let total: usize = self.gap.iter().map(|(_, n)| n).sum();
            out.push_str(&format!("{:<34}{total:>7}\n", "Total gap scenarios"));
        }
        out
    }

    fn render_main(&self, out: &mut String) {
        let line = |out: &mut String, name: &str, row: [usize; 3]| {
            let total: usize = row.iter().sum();
            out.push_str(&format!(
                "{name:<34}{:>6}{:>8}{:>6}{:>7}\n",
                row[0], row[1], row[2], total
            ));
        };
        out.push_str(&format!(
            "{:<34}{:>6}{:>8}{:>6}{:>7}\n",
            "factor", "low", "medium", "high", "total"
        ));
        for &(f, row) in &self.by_factor {
            line(out, f.as_str(), row);
        }
        out.push('\n');
        for (name, row) in self.paper_rows() {
            line(out, name, row);
        }
        line(out, "Total scenarios", self.totals());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_are_valid_and_follow_the_factor_rules() {
        for file in generate_suite() {
            file.validate("generated").unwrap();
            assert_eq!(file.episodes.len(), file.factor.configurations(file.complexity));
            for e in &file.episodes {
                assert_eq!(e.source_subtasks.len(), file.complexity.subtasks());
                let levels: Vec<(u8, u8)> = e
                    .source_subtasks
                    .iter()
                    .zip(&e.target_subtasks)
                    .map(|(s, t)| (s.obst_level, t.obst_level))
                    .collect();
                match file.factor {
                    Factor::Obst => assert!(levels.iter().all(|&(s, t)| s == 0 && t >= 1)),
                    Factor::Affo => assert!(levels.iter().all(|&(s, t)| s >= 1 && t == 0)),
                    Factor::Grip | Factor::Vacu => assert!(levels.iter().all(|&l| l == (0, 0))),
                    Factor::Comb => assert!(levels.iter().any(|(s, t)| s != t), "{levels:?}"),
                }
                let swap = (e.source_embodiment, e.target_embodiment);
                match file.factor {
                    Factor::Grip => assert_eq!(swap, (Embodiment::Finger, Embodiment::Vacuum)),
                    Factor::Vacu => assert_eq!(swap, (Embodiment::Vacuum, Embodiment::Finger)),
                    Factor::Obst | Factor::Affo => assert_eq!(swap, (Embodiment::Finger, Embodiment::Finger)),
                    Factor::Comb => {}
                }
                assert!(
                    e.source_subtasks
                        .iter()
                        .all(|s| s.multi_level == file.complexity.multi_level())
                );
            }
            if file.factor == Factor::Comb {
                let (finger, vacuum, none) = comb_embodiments(file.complexity);
                let count = |a, b| {
                    file.episodes
                        .iter()
                        .filter(|e| (e.source_embodiment, e.target_embodiment) == (a, b))
                        .count()
                };
                assert_eq!(count(Embodiment::Finger, Embodiment::Vacuum), finger);
                assert_eq!(count(Embodiment::Vacuum, Embodiment::Finger), vacuum);
                assert_eq!(count(Embodiment::Finger, Embodiment::Finger), none);
            }
        }
    }

    #[test]
    fn the_gap_suite_appends_subtasks_to_a_shared_demonstration() {
        let files = generate_gap_suite();
        assert_eq!(files.len(), GAP_ADDED.len());
        for (file, &added) in files.iter().zip(&GAP_ADDED) {
            file.validate("generated").unwrap();
            assert_eq!(file.added_subtasks, Some(added));
            assert_eq!(file.file_name(), format!("gap_obst_plus{added}.json"));
            assert_eq!(file.episodes.len(), GAP_CONFIGURATIONS);
            for (e, base) in file.episodes.iter().zip(&files[0].episodes) {
                // The same demonstration at every gap; the target keeps it first.
                assert_eq!(e.source_subtasks, base.source_subtasks);
                assert_eq!(e.source_subtasks.len(), 1);
                assert_eq!(e.target_subtasks.len(), 1 + usize::from(added));
                assert_eq!(e.target_subtasks[0].kind, e.source_subtasks[0].kind);
                assert_eq!(e.target_subtasks[0].variant, e.source_subtasks[0].variant);
                // Obstruction: a clean demonstration, every target subtask obstructed.
                assert_eq!(e.source_subtasks[0].obst_level, 0);
                assert!(e.target_subtasks.iter().all(|t| t.obst_level >= 1));
                assert!(
                    base.target_subtasks
                        .iter()
                        .zip(&e.target_subtasks)
                        .all(|(a, b)| a == b)
                );
            }
        }
        let all = scenarios(&files);
        assert_eq!(all.len(), 80);
        let s = find(&files, "gap_obst_plus2_03_s1").unwrap();
        assert_eq!((s.added_subtasks, s.seed), (Some(2), 1));
        let scenes = s.scenes().unwrap();
        assert_eq!(scenes.target.scene.goals.len(), 3);
        assert_eq!(scenes.source.scene.goals.len(), 1);
        // None of them is among the 440.
        let main = scenarios(&generate_suite());
        assert!(
            main.iter()
                .all(|m| m.added_subtasks.is_none() && !m.id.starts_with("gap_"))
        );
        // A target that does not start with the demonstration is refused, naming the field.
        let mut bad = files[1].clone();
        bad.episodes[4].target_subtasks.swap(0, 1);
        let err = ConfigFile::from_json_str(&bad.to_json_pretty(), "g.json")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("g.json") && err.contains("episodes[4].target_subtasks"),
            "{err}"
        );
        let back = ConfigFile::from_json_str(&files[3].to_json_pretty(), "g.json").unwrap();
        assert_eq!(back, files[3]);
        assert!(
            !generate_file(Factor::Obst, Complexity::Low)
                .to_json_pretty()
                .contains("added_subtasks")
        );
    }

    #[test]
    fn gap_scenarios_are_counted_apart_from_table_6_and_parse_to_their_target_complexity() {
        let gap = scenarios(&generate_gap_suite());
        for s in &gap {
            let added = s.added_subtasks.unwrap();
            let target_subtasks = s.episode.target_subtasks.len();
            assert_eq!(target_subtasks, 1 + usize::from(added), "{}", s.id);
            assert_eq!(
                nesy_core::benchmark::parse_scenario_id(&s.id),
                Some((GAP_FACTOR, Complexity::of_subtask_count(target_subtasks))),
                "{}",
                s.id
            );
        }
        let mut mixed = scenarios(&generate_suite());
        mixed.extend(gap.iter().cloned());
        let table = CountTable::of(&mixed);
        assert_eq!(table.totals(), [160, 160, 120], "Table 6 holds only the 440");
        assert_eq!(table.gap, vec![(0, 20), (1, 20), (2, 20), (3, 20)]);
        let text = table.render();
        assert!(
            text.contains("Total scenarios                      160     160   120    440"),
            "{text}"
        );
        assert!(
            text.contains("not part of the 440")
                && text
                    .lines()
                    .any(|l| l.split_whitespace().eq(["Total", "gap", "scenarios", "80"])),
            "{text}"
        );
        // A suite folder of gap files alone prints only the gap counts.
        let alone = CountTable::of(&gap).render();
        assert!(
            !alone.contains("Total scenarios") && alone.contains("+3"),
            "{alone}"
        );
        assert!(
            !CountTable::of(&scenarios(&generate_suite()))
                .render()
                .contains("gap")
        );
    }

    #[test]
    fn json_round_trip_and_errors_name_the_field() {
        let file = generate_file(Factor::Comb, Complexity::Medium);
        let back = ConfigFile::from_json_str(&file.to_json_pretty(), "x.json").unwrap();
        assert_eq!(back, file);
        let text = file
            .to_json_pretty()
            .replacen("\"put_in_hinge\"", "\"put_in_fridge\"", 1);
        let err = ConfigFile::from_json_str(&text, "x.json")
            .unwrap_err()
            .to_string();
        assert!(err.contains("x.json") && err.contains("kind"), "{err}");
        let mut bad = file.clone();
        bad.episodes[2].target_subtasks[0].variant += 1;
        let err = ConfigFile::from_json_str(&bad.to_json_pretty(), "x.json")
            .unwrap_err()
            .to_string();
        assert!(err.contains("episodes[2].target_subtasks"), "{err}");
    }

    #[test]
    fn seeds_give_different_scenes_with_shared_layouts() {
        let files = generate_suite();
        let a = find(&files, "obst_low_03_s0").unwrap().scenes().unwrap();
        let b = find(&files, "obst_low_03_s1").unwrap().scenes().unwrap();
        assert_ne!(a.source.scene.objects, b.source.scene.objects);
        // Source and target share the objects and their names.
        let names = |t: &GeneratedTask| t.scene.objects.iter().map(|o| o.name.clone()).collect::<Vec<_>>();
        assert_eq!(names(&a.source), names(&a.target));
        assert_eq!(a.goal_label(), a.source.goal_label.as_slice());
        assert!(find(&files, "obst_low_15_s0").is_err());
    }
}
