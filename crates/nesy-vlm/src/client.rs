//! The client: builds the wire body through the backend profile, then calls the transport
//! under a concurrency cap and the retry policy, and accounts for every call.

use std::sync::{Arc, Mutex};

use tokio::sync::{OnceCell, Semaphore};
use tokio::time::Instant;

use crate::accounting::{CallRecord, PriceTable, RunUsage};
use crate::capabilities::{ServerCapabilities, estimate_prompt_tokens};
use crate::cassette::{CassetteMode, CassetteOptions, CassetteTransport};
use crate::config::{ConfigError, VlmConfig};
use crate::error::{ProviderError, TransportError, VlmError};
use crate::profile::{AuthScheme, Profile};
use crate::request::{ChatRequest, Part};
use crate::response::{ChatResponse, parse_completion};
use crate::retry::{RetryPolicy, status_is_retryable};
use crate::secret::SecretString;
use crate::transport::Auth;
use crate::transport::{HttpTransport, Origin, Transport, WireRequest, WireResponse};

/// The smallest reply worth asking for; a prompt leaving less room is refused before it is
/// sent.
const MIN_REPLY_TOKENS: u32 = 64;

/// Where re-ask turns start in a conversation: after the system prompt and the task.
const FIRST_FOLLOW_UP: usize = 2;

/// Whether the conversation holds a rejected reply and its correction after the system
/// prompt and the task, with at least one later turn, so that leaving them out keeps the
/// latest exchange.
fn oldest_follow_up_is_droppable(request: &ChatRequest) -> bool {
    use crate::request::Role;
    let role = |i: usize| request.messages[i].role;
    request.messages.len() > FIRST_FOLLOW_UP + 2
        && matches!(role(0), Role::System | Role::Developer)
        && role(1) == Role::User
        && role(FIRST_FOLLOW_UP) == Role::Assistant
        && role(FIRST_FOLLOW_UP + 1) == Role::User
}

/// `tokens` times `scale`, rounded up.
fn scaled(tokens: u32, scale: f64) -> u32 {
    if scale <= 1.0 {
        return tokens;
    }
    let value = (f64::from(tokens) * scale).ceil();
    if value >= f64::from(u32::MAX) {
        u32::MAX
    } else {
        value as u32
    }
}

/// [`estimate_prompt_tokens`] of a whole request.
fn estimate_request_tokens(request: &ChatRequest) -> u32 {
    let text_bytes: usize = request
        .messages
        .iter()
        .flat_map(|m| &m.parts)
        .map(|part| match part {
            Part::Text(text) => text.len(),
            Part::Image(_) => 0,
        })
        .sum();
    estimate_prompt_tokens(text_bytes, request.messages.len(), request.image_count())
}

/// An OpenAI-compatible chat client. Cheap to clone; clones share the transport, the
/// concurrency cap and the run's accounting.
#[derive(Clone)]
pub struct VlmClient {
    inner: Arc<Inner>,
}

struct Inner {
    profile: Profile,
    transport: Arc<dyn Transport>,
    retry: RetryPolicy,
    concurrency: Semaphore,
    max_concurrency: usize,
    max_images_per_request: Option<usize>,
    prices: PriceTable,
    usage: Mutex<RunUsage>,
    /// The configured key, redacted from every provider error by its exact text.
    api_key: Option<SecretString>,
    /// What the server announced, read before the first call.
    capabilities: OnceCell<ServerCapabilities>,
}

impl std::fmt::Debug for VlmClient {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("VlmClient")
            .field("profile", &self.inner.profile)
            .field("transport", &self.inner.transport)
            .field("max_concurrency", &self.inner.max_concurrency)
            .finish()
    }
}

impl VlmClient {
    /// Builds the client a configuration describes: HTTP when calls must go live, wrapped in
    /// a cassette when one is configured. In `none` mode (and `once` with an existing file)
    /// no HTTP client is built, so no key is needed.
    pub fn from_config(config: &VlmConfig) -> Result<Self, VlmError> {
        let live: Option<Arc<dyn Transport>> = if Self::may_go_live(config) {
            Some(Arc::new(Self::http_transport(config)?))
        } else {
            None
        };
        Self::assemble(config, live, Some(config.backend.as_str().to_string()))
    }

    /// Like [`VlmClient::from_config`], but with `inner` in place of HTTP (for example an
    /// offline responder): the configured cassette, if any, records and replays around it.
    pub fn from_config_over(config: &VlmConfig, inner: Arc<dyn Transport>) -> Result<Self, VlmError> {
        // The cassette's backend label comes from the inner transport.
        Self::assemble(config, Some(inner), None)
    }

    /// Whether the configured cassette mode can send a call to the inner transport.
    fn may_go_live(config: &VlmConfig) -> bool {
        match &config.cassette {
            None => true,
            Some(cassette) => match cassette.mode {
                CassetteMode::None => false,
                CassetteMode::Once => !cassette.path.exists(),
                CassetteMode::NewEpisodes | CassetteMode::All => true,
            },
        }
    }

    fn assemble(
        config: &VlmConfig,
        live: Option<Arc<dyn Transport>>,
        backend_label: Option<String>,
    ) -> Result<Self, VlmError> {
        let mut config = config.clone();
        let transport: Arc<dyn Transport> = match &config.cassette {
            Some(cassette) => {
                let transport = CassetteTransport::open(
                    &cassette.path,
                    cassette.mode,
                    live,
                    CassetteOptions {
                        strict: cassette.strict,
                        usage_report: cassette.usage_report.clone(),
                        backend: backend_label,
                        ..CassetteOptions::recording(&config)
                    },
                )?;
                // A pure replay builds its bodies as the recording did, so that they match.
                if cassette.mode == CassetteMode::None {
                    config.defaults.constrain = transport.recorded_constrain();
                }
                Arc::new(transport)
            }
            None => live.ok_or_else(|| VlmError::InvalidRequest("no transport configured".into()))?,
        };
        Ok(Self::with_transport(&config, transport))
    }

    /// The live HTTP transport for a configuration (checks that a required key is set).
    pub fn http_transport(config: &VlmConfig) -> Result<HttpTransport, VlmError> {
        let profile = config.profile();
        let key = config.api_key.clone().filter(|key| !key.is_empty());
        if key.is_none() && config.backend.requires_api_key() {
            let var = match profile.auth {
                AuthScheme::ApiKeyHeader => "AZURE_OPENAI_API_KEY",
                AuthScheme::Bearer => "OPENAI_API_KEY",
            };
            return Err(ConfigError::Missing {
                what: "API key",
                hint: format!(
                    "the {} backend needs one: set {var} or NESY_VLM_API_KEY",
                    config.backend
                ),
            }
            .into());
        }
        let auth = match (key, profile.auth) {
            (None, _) => Auth::None,
            (Some(key), AuthScheme::Bearer) => Auth::Bearer(key),
            (Some(key), AuthScheme::ApiKeyHeader) => Auth::ApiKeyHeader(key),
        };
        HttpTransport::new(
            &config.base_url,
            auth,
            &config.timeouts,
            format!("http {}", config.backend),
        )
        .map(|transport| transport.with_probe(config.backend, config.model.clone()))
        .map_err(|message| {
            ConfigError::Invalid {
                origin: "base URL".into(),
                message,
            }
            .into()
        })
    }

    /// A client over any transport (a cassette, an offline responder, a test double).
    pub fn with_transport(config: &VlmConfig, transport: Arc<dyn Transport>) -> Self {
        let max_concurrency = config.max_concurrency.max(1);
        Self {
            inner: Arc::new(Inner {
                profile: config.profile(),
                transport,
                retry: config.retry,
                concurrency: Semaphore::new(max_concurrency),
                max_concurrency,
                max_images_per_request: config.max_images_per_request,
                prices: config.prices.clone(),
                usage: Mutex::new(RunUsage::default()),
                api_key: config.api_key.clone(),
                capabilities: OnceCell::new(),
            }),
        }
    }

    /// The resolved backend profile.
    pub fn profile(&self) -> &Profile {
        &self.inner.profile
    }

    /// The transport under the retry layer.
    pub fn transport(&self) -> &Arc<dyn Transport> {
        &self.inner.transport
    }

    /// The wire request a chat request becomes (body through the profile, task context and
    /// purpose carried beside it).
    pub fn wire_request(&self, request: &ChatRequest) -> WireRequest {
        WireRequest {
            path: self.inner.profile.path.clone(),
            body: self.inner.profile.build_body(request),
            task: request.task.clone(),
            purpose: request.purpose.clone(),
        }
    }

    /// What the server announced it can take (image input, context window), read from the
    /// transport once and kept for the client's life.
    pub async fn capabilities(&self) -> ServerCapabilities {
        self.inner
            .capabilities
            .get_or_init(|| self.inner.transport.capabilities())
            .await
            .clone()
    }

    /// The output-token cap a request is sent with ([`Profile::output_cap`]).
    pub fn effective_cap(&self, request: &ChatRequest) -> Option<u32> {
        self.inner.profile.output_cap(request)
    }

    /// `chat` with the constraint `build` makes, when this client sends constraints at all
    /// (`constrain = auto`); under `off` the constraint is not even built, so callers that
    /// never send one (the offline responder) pay nothing for it.
    pub fn constrain(
        &self,
        chat: ChatRequest,
        build: impl FnOnce() -> crate::constraint::ReplyConstraint,
    ) -> ChatRequest {
        match self.inner.profile.defaults.constrain {
            crate::constraint::ConstrainMode::Auto => chat.constraint(build()),
            crate::constraint::ConstrainMode::Off => chat,
        }
    }

    /// The form `request`'s reply takes under this client's backend and constrain mode
    /// ([`Profile::reply_form`]).
    pub fn reply_form(&self, request: &ChatRequest) -> crate::constraint::ReplyForm {
        self.inner.profile.reply_form(request)
    }

    /// Checks `request` against what the server announced, and sizes its reply to the room
    /// the context window leaves: pictures never go to a server that takes none, and a
    /// prompt that would not fit is not sent at all. `scale` corrects the token estimate
    /// when the server has said how far off it was.
    fn fit_to_server(
        &self,
        mut request: ChatRequest,
        caps: &ServerCapabilities,
        scale: f64,
    ) -> Result<ChatRequest, VlmError> {
        let images = request.image_count();
        if images > 0 && caps.refuses_images() {
            return Err(VlmError::Unsupported {
                capability: "image input".into(),
                detail: format!(
                    "{} announces text input only, and this request carries {images} image(s); it was not sent",
                    caps.source_label()
                ),
            });
        }
        let Some(context) = caps.context_tokens else {
            return Ok(request);
        };
        // The room a reply needs: its cap, but never more than a quarter of the window, so a
        // large cap on a small server does not push out the conversation itself.
        let wanted = self
            .effective_cap(&request)
            .unwrap_or(u32::MAX)
            .min(context / 4)
            .max(MIN_REPLY_TOKENS);
        // A conversation of re-asks that outgrows the window loses its oldest rejected
        // reply and correction first; the task and the latest turns stay.
        let estimate = |request: &ChatRequest| scaled(estimate_request_tokens(request), scale);
        let mut estimated = estimate(&request);
        let mut dropped = 0;
        while estimated.saturating_add(wanted) > context && oldest_follow_up_is_droppable(&request) {
            request.messages.drain(FIRST_FOLLOW_UP..FIRST_FOLLOW_UP + 2);
            dropped += 1;
            estimated = estimate(&request);
        }
        if dropped > 0 {
            tracing::info!(
                purpose = request.purpose.as_deref().unwrap_or("-"),
                "left out the {dropped} oldest re-ask turn(s) to fit the server's {context}-token context"
            );
        }
        let room = context.saturating_sub(estimated);
        if room < MIN_REPLY_TOKENS {
            return Err(VlmError::ContextExceeded { estimated, context });
        }
        if self.effective_cap(&request).is_none_or(|cap| cap > room) {
            request.max_output_tokens = Some(room);
        }
        Ok(request)
    }

    /// Sends one chat request: retries transient failures, respects the concurrency cap,
    /// and records usage, latency and attempts whatever the outcome.
    pub async fn chat(&self, request: ChatRequest) -> Result<ChatResponse, VlmError> {
        if request.messages.is_empty() {
            return Err(VlmError::InvalidRequest(
                "a chat request needs at least one message".into(),
            ));
        }
        if let Some(limit) = self.inner.max_images_per_request {
            let images = request.image_count();
            if images > limit {
                return Err(VlmError::TooManyImages { images, limit });
            }
        }
        let caps = self.capabilities().await;
        // Kept for a second fit when the server says the estimate was short of its count.
        let original = caps.context_tokens.map(|_| request.clone());
        let fitted = self.fit_to_server(request, &caps, 1.0)?;
        let outcome = self.send_fitted(&fitted, &caps).await;
        let (Some(original), Err(VlmError::Http { provider, .. })) = (original, &outcome) else {
            return outcome;
        };
        let estimated = estimate_request_tokens(&fitted);
        match provider.prompt_tokens_over_context() {
            // The prompt is larger than estimated (the tokenizer packs this text less
            // densely): fit it again with the server's own count, once.
            Some(actual) if actual > estimated => {
                let scale = f64::from(actual) / f64::from(estimated.max(1));
                tracing::info!(
                    purpose = original.purpose.as_deref().unwrap_or("-"),
                    "the server counted {actual} prompt tokens where {estimated} were estimated; fitting the request again"
                );
                let refitted = self.fit_to_server(original, &caps, scale)?;
                self.send_fitted(&refitted, &caps).await
            }
            _ => outcome,
        }
    }

    /// Sends a request already fitted to the server and records it.
    async fn send_fitted(
        &self,
        request: &ChatRequest,
        caps: &ServerCapabilities,
    ) -> Result<ChatResponse, VlmError> {
        let sent_cap = self.effective_cap(request);
        let wire = self.wire_request(request);
        let started = Instant::now();
        let (result, attempts, origin) = self.send_with_retries(&wire).await;
        let (mut outcome, usage) = match result {
            Ok(response) => self.read_success(response, attempts, started),
            Err(err) => (Err(err), None),
        };
        // Only the client knows what the request was sent with; the cut is judged by it.
        if let Err(VlmError::Truncated { cap, context, .. }) = &mut outcome {
            *cap = sent_cap;
            *context = caps.context_tokens;
        }
        let record = CallRecord {
            model: self.inner.profile.model.clone(),
            purpose: request.purpose.clone(),
            usage,
            started: started.into_std(),
            latency: started.elapsed(),
            attempts,
            origin,
            succeeded: outcome.is_ok(),
        };
        self.inner
            .usage
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .record(&record, &self.inner.prices);
        outcome.map(|mut response| {
            response.latency = record.latency;
            response
        })
    }

    async fn send_with_retries(
        &self,
        wire: &WireRequest,
    ) -> (Result<WireResponse, VlmError>, u32, Option<Origin>) {
        let policy = &self.inner.retry;
        let mut attempts = 0;
        loop {
            attempts += 1;
            let sent = {
                // Held for the attempt only, not the back-off, so waiting calls do not block others.
                let Ok(_permit) = self.inner.concurrency.acquire().await else {
                    return (
                        Err(VlmError::InvalidRequest("the client was shut down".into())),
                        attempts,
                        None,
                    );
                };
                self.inner.transport.send(wire).await
            };
            let can_retry = attempts < policy.max_attempts;
            match sent {
                Ok(response) if response.is_success() => {
                    let origin = response.origin;
                    return (Ok(response), attempts, Some(origin));
                }
                Ok(response) => {
                    let mut provider = ProviderError::from_body(&response.body);
                    if let Some(key) = &self.inner.api_key {
                        provider = provider.without_secret(key);
                    }
                    if can_retry && status_is_retryable(&response, &provider) {
                        let delay = policy.delay(attempts, Some(&response));
                        tracing::warn!(
                            status = response.status,
                            attempt = attempts,
                            ?delay,
                            "retrying: {provider}"
                        );
                        // A replayed failure is not waited for: the recording already waited.
                        if response.origin == Origin::Live {
                            tokio::time::sleep(delay).await;
                        }
                        continue;
                    }
                    let error = VlmError::Http {
                        status: response.status,
                        path: wire.path.clone(),
                        request_id: response.request_id().map(str::to_string),
                        provider: Box::new(provider),
                        attempts,
                    };
                    return (Err(error), attempts, Some(response.origin));
                }
                // A cassette error (a replay miss) is the cassette's to explain, not the network's.
                Err(TransportError::Cassette(err)) => return (Err(VlmError::Cassette(err)), attempts, None),
                Err(err) => {
                    if can_retry && err.is_retryable() {
                        let delay = policy.delay(attempts, None);
                        tracing::warn!(
                            attempt = attempts,
                            ?delay,
                            "retrying after transport error: {err}"
                        );
                        tokio::time::sleep(delay).await;
                        continue;
                    }
                    return (Err(VlmError::Transport { error: err, attempts }), attempts, None);
                }
            }
        }
    }

    fn read_success(
        &self,
        response: WireResponse,
        attempts: u32,
        started: Instant,
    ) -> (Result<ChatResponse, VlmError>, Option<crate::response::Usage>) {
        let request_id = response.request_id().map(str::to_string);
        match parse_completion(response.status, &response.body, request_id.as_deref()) {
            Err(err) => (Err(err), None),
            Ok((parsed, Some(err))) => (Err(err), parsed.usage),
            Ok((parsed, None)) => {
                let usage = parsed.usage;
                let chat = ChatResponse {
                    text: parsed.text,
                    finish_reason: parsed.finish_reason,
                    usage: parsed.usage,
                    model: parsed.model,
                    response_id: parsed.response_id,
                    request_id,
                    latency: started.elapsed(),
                    attempts,
                    origin: response.origin,
                    content_was_null: parsed.content_was_null,
                };
                (Ok(chat), usage)
            }
        }
    }

    /// Usage of the run so far.
    pub fn usage(&self) -> RunUsage {
        self.inner
            .usage
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .clone()
    }

    /// Ends the run: lets the transport finish (a cassette writes its usage report and, in
    /// strict mode, fails on unused interactions) and returns the run's usage.
    pub fn finish(&self) -> Result<RunUsage, VlmError> {
        self.inner.transport.finish()?;
        Ok(self.usage())
    }
}
