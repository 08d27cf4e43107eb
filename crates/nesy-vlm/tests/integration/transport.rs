//! The transport extension point: a transport of our own (here a stand-in for the offline
//! responder a later issue adds) plugs in under the client and under a cassette without any
//! change to either, and receives the task context that never goes on the wire.

use std::sync::{Arc, Mutex};

use nesy_vlm::{
    BackendKind, BoxFuture, CassetteMode, CassetteSettings, ChatRequest, Message, Origin, TaskContext,
    Transport, TransportError, VlmClient, WireRequest, WireResponse,
};
use serde_json::json;

/// Answers with `task.data["answer"]`, remembering the task kinds it saw.
#[derive(Debug, Default)]
struct AnswerFromTask {
    seen: Mutex<Vec<String>>,
}

impl Transport for AnswerFromTask {
    fn send<'a>(&'a self, request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        Box::pin(async move {
            let task = request.task.as_ref().ok_or_else(|| TransportError::Failed {
                message: "no task context".into(),
                retryable: false,
            })?;
            self.seen.lock().unwrap().push(task.kind.clone());
            let body = nesy_testkit::completion(task.data["answer"].as_str().unwrap_or_default());
            Ok(WireResponse::new(
                200,
                serde_json::to_vec(&body).unwrap(),
                Origin::Offline,
            ))
        })
    }

    fn label(&self) -> String {
        "offline answer-from-task".into()
    }
}

fn request(answer: &str) -> ChatRequest {
    ChatRequest::new()
        .message(Message::user_text("Which operator explains this transition?"))
        .task(TaskContext::new("induce_operator", json!({"answer": answer})))
}

#[tokio::test]
async fn a_custom_transport_plugs_in_under_the_client_and_a_cassette() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("offline.json");
    let mut cfg = nesy_testkit::mock_config(BackendKind::OpenAi, "gpt-5", "http://127.0.0.1:9");
    cfg.cassette = Some(CassetteSettings {
        path: path.clone(),
        mode: CassetteMode::All,
        strict: false,
        usage_report: None,
    });

    let offline = Arc::new(AnswerFromTask::default());
    let client = VlmClient::from_config_over(&cfg, offline.clone()).unwrap();
    let reply = client.chat(request("(:action open-drawer)")).await.unwrap();
    assert_eq!(reply.text, "(:action open-drawer)");
    assert_eq!(reply.origin, Origin::Offline);
    assert_eq!(*offline.seen.lock().unwrap(), ["induce_operator"]);
    assert_eq!(client.usage().total.offline_calls, 1);

    // The wire body and the cassette never contain the task context.
    let wire = client.wire_request(&request("secret plan"));
    assert!(!wire.body.to_string().contains("secret plan"));
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        !text.contains("induce_operator") && text.contains("offline answer-from-task"),
        "{text}"
    );

    // Replaying needs neither the transport nor the network.
    cfg.cassette.as_mut().unwrap().mode = CassetteMode::None;
    let replay = VlmClient::from_config(&cfg).unwrap();
    let replayed = replay.chat(request("(:action open-drawer)")).await.unwrap();
    assert_eq!(
        (replayed.text.as_str(), replayed.origin),
        ("(:action open-drawer)", Origin::Replayed)
    );
}
