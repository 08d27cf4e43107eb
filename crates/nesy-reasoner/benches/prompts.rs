//! Benchmarks of the reasoner's request building: NeSyCR's requests rendered from the ones
//! nesy-core's adaptation loop makes on a worked scenario (template rendering, few-shot
//! examples projected onto the tier, the task context serialised to JSON, six 384×384
//! keyframe images attached), and the program taken out of a code-generation reply.
//!
//! `cargo bench -p nesy-reasoner --bench prompts`

use std::sync::Arc;
use std::time::Duration;

use criterion::{Criterion, criterion_group};
use nesy_vlm::{BackendKind, Image, Transport, VlmClient, VlmConfig};

#[path = "../tests/integration/scenario.rs"]
#[allow(missing_docs, dead_code)]
mod scenario;

fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("runtime")
}

/// Two views rendered by nesy-sim, kept beside the client's benchmark.
fn rendered_views() -> (Vec<u8>, Vec<u8>) {
    let data = nesy_testkit::workspace_root().join("crates/nesy-vlm/benches/data");
    let read = |name: &str| std::fs::read(data.join(name)).expect("benchmark image");
    (read("top.png"), read("front.png"))
}

/// The prompt layer: the scenario's real requests rendered into chat requests.
fn prompts(c: &mut Criterion) {
    use nesy_core::adapt::{InductionRequest, PatchRequest, Reasoner, ReasonerError};

    #[derive(Default)]
    struct Recorder {
        replies: Vec<&'static str>,
        patches: Vec<&'static str>,
        induction: Vec<InductionRequest>,
        patch: Vec<PatchRequest>,
    }
    impl Reasoner for Recorder {
        async fn induce_operator(&mut self, r: &InductionRequest) -> Result<String, ReasonerError> {
            self.induction.push(r.clone());
            Ok(self.replies.remove(0).into())
        }
        async fn propose_patch(&mut self, r: &PatchRequest) -> Result<String, ReasonerError> {
            self.patch.push(r.clone());
            Ok(self.patches.remove(0).into())
        }
    }
    let mut recorder = Recorder {
        replies: vec![
            scenario::APPROACH,
            scenario::GRASP,
            scenario::CARRY,
            scenario::DROP,
        ],
        patches: vec![scenario::PATCH],
        ..Recorder::default()
    };
    let adaptation = runtime()
        .block_on(nesy_core::adapt::run(
            &mut recorder,
            &scenario::demo(),
            &scenario::target(),
            &scenario::config(),
        ))
        .expect("scenario adapts");
    let (top, front) = rendered_views();
    let views = |_| {
        nesy_reasoner::Views::new([
            ("top", Image::png(top.clone()).expect("png")),
            ("front", Image::png(front.clone()).expect("png")),
            ("back", Image::png(top.clone()).expect("png")),
        ])
    };
    let keyframes = Arc::new(nesy_reasoner::KeyframeList {
        views: (0..5).map(views).collect(),
    });
    let client = VlmClient::with_transport(
        &VlmConfig::new(BackendKind::OpenAi, "gpt-5"),
        Arc::new(nesy_testkit::InFlightCounter::new(Arc::new(NeverSends))),
    );
    let reasoner = nesy_reasoner::VlmReasoner::new(client)
        .expect("prompts")
        .with_keyframes(keyframes);
    let prompts = nesy_reasoner::prompts::Prompts::builtin().expect("prompts");
    let codegen = nesy_reasoner::codegen::CodeGenerationRequest {
        instruction: "Put the fruits in the hinge box.".into(),
        objects: scenario::OBJECTS.iter().map(|o| o.to_string()).collect(),
        procedure: adaptation.outcome.procedure().to_vec(),
        plan: Vec::new(),
        embodiment: nesy_core::Embodiment::Vacuum,
        extended: true,
        tools: false,
        protective_stop: false,
    };
    let mut group = c.benchmark_group("prompts");
    group.bench_function("induction_request_6_rendered_images", |b| {
        b.iter(|| {
            reasoner
                .induction_request(&recorder.induction[3])
                .expect("renders")
        })
    });
    group.bench_function("refinement_request", |b| {
        b.iter(|| reasoner.patch_request(&recorder.patch[0]).expect("renders"))
    });
    group.bench_function("code_generation_extended_request", |b| {
        b.iter(|| {
            nesy_reasoner::codegen::build_request(&prompts, &codegen, &Default::default()).expect("renders")
        })
    });
    group.bench_function("extract_code", |b| {
        b.iter(|| nesy_reasoner::codegen::extract_code(scenario::CODE).expect("a program"))
    });
    group.finish();
}

/// The prompt benchmarks only build requests.
#[derive(Debug)]
struct NeverSends;

impl Transport for NeverSends {
    fn send<'a>(
        &'a self,
        _: &'a nesy_vlm::WireRequest,
    ) -> nesy_vlm::BoxFuture<'a, Result<nesy_vlm::WireResponse, nesy_vlm::TransportError>> {
        Box::pin(async {
            Err(nesy_vlm::TransportError::Failed {
                message: "benchmarks never send".into(),
                retryable: false,
            })
        })
    }
    fn label(&self) -> String {
        "never".into()
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    targets = prompts
}

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
