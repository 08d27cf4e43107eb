//! A transport wrapper around each unit's model calls: it counts calls and images by purpose,
//! stops a unit at its call cap, and bounds model calls in flight across every unit of the
//! run (model calls wait on the endpoint, not on the CPU, so they have their own limit).

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use nesy_vlm::TransportError;
use nesy_vlm::VlmError;
use nesy_vlm::{BoxFuture, ServerCapabilities, Transport, WireRequest, WireResponse};
use tokio::sync::Semaphore;

/// What a unit's calls came to.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CallCounts {
    /// Calls answered by the server (each attempt that got a response, error statuses
    /// included). A send that got no response at all (a timeout, a dropped connection) is
    /// not counted: no recording keeps it, and a replay must count what the live run did.
    pub calls: u64,
    /// Sends in flight, held against the cap until they end.
    pub pending: u64,
    /// Images sent.
    pub images: u64,
    /// Calls by purpose.
    pub by_purpose: BTreeMap<String, u64>,
    /// True once the cap refused a call.
    pub cap_reached: bool,
}

/// Counts and caps one unit's calls.
#[derive(Debug)]
pub struct Metered {
    inner: Arc<dyn Transport>,
    counts: Arc<Mutex<CallCounts>>,
    cap: Option<u64>,
    in_flight: Arc<Semaphore>,
}

/// The number of image parts in a chat-completions body.
pub fn image_count(body: &serde_json::Value) -> u64 {
    body.get("messages")
        .and_then(|m| m.as_array())
        .map(|messages| {
            messages
                .iter()
                .filter_map(|m| m.get("content").and_then(|c| c.as_array()))
                .flatten()
                .filter(|part| part.get("type").and_then(|t| t.as_str()) == Some("image_url"))
                .count() as u64
        })
        .unwrap_or(0)
}

impl Metered {
    /// Wraps `inner`, refusing calls beyond `cap` and waiting on `in_flight` for a slot.
    pub fn new(inner: Arc<dyn Transport>, cap: Option<u64>, in_flight: Arc<Semaphore>) -> Metered {
        Metered {
            inner,
            counts: Arc::new(Mutex::new(CallCounts::default())),
            cap,
            in_flight,
        }
    }

    /// The counts so far (shared with the transport).
    pub fn counts(&self) -> Arc<Mutex<CallCounts>> {
        self.counts.clone()
    }
}

impl Transport for Metered {
    fn send<'a>(&'a self, request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        Box::pin(async move {
            {
                let mut c = self.counts.lock().unwrap_or_else(|e| e.into_inner());
                if self.cap.is_some_and(|cap| c.calls + c.pending >= cap) {
                    c.cap_reached = true;
                    return Err(TransportError::Failed {
                        message: format!(
                            "the unit's cap of {} model call(s) is reached (--max-calls-per-unit)",
                            self.cap.unwrap_or_default()
                        ),
                        retryable: false,
                    });
                }
                c.pending += 1;
            }
            let result = match self.in_flight.acquire().await {
                Ok(_slot) => self.inner.send(request).await,
                Err(_) => Err(TransportError::Failed {
                    message: "the run is shutting down".into(),
                    retryable: false,
                }),
            };
            let mut c = self.counts.lock().unwrap_or_else(|e| e.into_inner());
            c.pending -= 1;
            if result.is_ok() {
                c.calls += 1;
                c.images += image_count(&request.body);
                *c.by_purpose
                    .entry(request.purpose.clone().unwrap_or_else(|| "-".into()))
                    .or_default() += 1;
            }
            result
        })
    }

    fn label(&self) -> String {
        self.inner.label()
    }

    fn finish(&self) -> Result<(), VlmError> {
        self.inner.finish()
    }

    fn capabilities(&self) -> BoxFuture<'_, ServerCapabilities> {
        // What the server announces decides how requests are fitted to it (no pictures to a
        // text-only model, replies sized to the context window); the meter hides none of it.
        self.inner.capabilities()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_are_counted_in_every_message() {
        let body = serde_json::json!({"messages": [
            {"role": "system", "content": "s"},
            {"role": "user", "content": [
                {"type": "text", "text": "a"},
                {"type": "image_url", "image_url": {"url": "data:"}},
                {"type": "image_url", "image_url": {"url": "data:"}}
            ]},
            {"role": "user", "content": [{"type": "image_url", "image_url": {"url": "data:"}}]}
        ]});
        assert_eq!(image_count(&body), 3);
        assert_eq!(image_count(&serde_json::json!({})), 0);
    }

    /// A text-only server with a 4,096-token window.
    #[derive(Debug)]
    struct Announcing;

    impl Transport for Announcing {
        fn send<'a>(&'a self, _: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
            Box::pin(async {
                Err(TransportError::Failed {
                    message: "not sent in this test".into(),
                    retryable: false,
                })
            })
        }

        fn label(&self) -> String {
            "announcing".into()
        }

        fn capabilities(&self) -> BoxFuture<'_, ServerCapabilities> {
            Box::pin(async {
                ServerCapabilities {
                    images: Some(false),
                    context_tokens: Some(4096),
                    source: Some("GET /props".into()),
                }
            })
        }
    }

    /// Fails its first send without a response, then answers.
    #[derive(Debug, Default)]
    struct FlakyOnce {
        sent: std::sync::atomic::AtomicUsize,
    }

    impl Transport for FlakyOnce {
        fn send<'a>(&'a self, _: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
            Box::pin(async move {
                if self.sent.fetch_add(1, std::sync::atomic::Ordering::SeqCst) == 0 {
                    return Err(TransportError::Failed {
                        message: "timed out".into(),
                        retryable: true,
                    });
                }
                Ok(WireResponse::new(200, "{}", nesy_vlm::Origin::Live))
            })
        }

        fn label(&self) -> String {
            "flaky".into()
        }
    }

    /// A send that got no response is not a call: no recording keeps it, and a replay of the
    /// unit must count what the live run counted.
    #[test]
    fn only_answered_sends_are_counted() {
        let metered = Metered::new(
            Arc::new(FlakyOnce::default()),
            Some(1),
            Arc::new(Semaphore::new(1)),
        );
        let request = WireRequest {
            path: "/chat/completions".into(),
            body: serde_json::json!({"messages": []}),
            task: None,
            purpose: Some("induce".into()),
        };
        assert!(pollster::block_on(metered.send(&request)).is_err());
        assert_eq!(metered.counts().lock().unwrap().calls, 0);
        assert!(pollster::block_on(metered.send(&request)).is_ok());
        assert_eq!(metered.counts().lock().unwrap().calls, 1);
        // The cap of one call is now reached.
        assert!(pollster::block_on(metered.send(&request)).is_err());
        assert!(metered.counts().lock().unwrap().cap_reached);
    }

    /// Under the meter the client still learns what the server takes, so a benchmark unit
    /// fits its requests to the server as `nesy adapt` does.
    #[test]
    fn the_meter_passes_on_what_the_server_announces() {
        let metered = Metered::new(Arc::new(Announcing), None, Arc::new(Semaphore::new(1)));
        let caps = pollster::block_on(metered.capabilities());
        assert_eq!((caps.images, caps.context_tokens), (Some(false), Some(4096)));
    }
}
