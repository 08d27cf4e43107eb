//! When to retry and how long to wait: the OpenAI SDK's rules (retry 408/409/429/5xx and
//! connection errors; honour `retry-after-ms`, then `retry-after`; otherwise back off
//! exponentially with jitter), except that `insufficient_quota` is never retried.

use std::hash::{BuildHasher, Hasher};
use std::time::{Duration, SystemTime};

use serde::{Deserialize, Serialize};

use crate::error::ProviderError;
use crate::transport::WireResponse;

/// How often and how patiently to retry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct RetryPolicy {
    /// Attempts per call, the first included (the SDK's default of two retries is 3).
    pub max_attempts: u32,
    /// Back-off before the first retry; doubles each retry.
    pub base_delay: Duration,
    /// Cap on the exponential back-off.
    pub max_delay: Duration,
    /// Longest server-requested wait (`retry-after`) that is honoured; longer requests fall
    /// back to the exponential back-off.
    pub max_retry_after: Duration,
}

impl Default for RetryPolicy {
    fn default() -> Self {
        Self {
            max_attempts: 3,
            base_delay: Duration::from_millis(500),
            max_delay: Duration::from_secs(8),
            max_retry_after: Duration::from_secs(120),
        }
    }
}

/// Whether a non-success response may succeed when repeated.
pub(crate) fn status_is_retryable(response: &WireResponse, provider: &ProviderError) -> bool {
    if provider.is_insufficient_quota() || provider.missing_capability().is_some() {
        return false;
    }
    match response.header("x-should-retry").map(str::trim) {
        Some(v) if v.eq_ignore_ascii_case("true") => return true,
        Some(v) if v.eq_ignore_ascii_case("false") => return false,
        _ => {}
    }
    status_may_pass(response.status)
}

/// Whether an HTTP status says the failure may pass on its own (a timeout, a conflict, rate
/// limiting, a server error), whatever the body says.
pub(crate) fn status_may_pass(status: u16) -> bool {
    matches!(status, 408 | 409 | 429) || status >= 500
}

impl RetryPolicy {
    /// The wait before the next attempt, after `failed_attempts` attempts have failed.
    pub(crate) fn delay(&self, failed_attempts: u32, response: Option<&WireResponse>) -> Duration {
        if let Some(requested) = response.and_then(|r| server_requested_delay(r, SystemTime::now()))
            && requested <= self.max_retry_after
        {
            return requested;
        }
        let exponent = failed_attempts.saturating_sub(1).min(30);
        let backoff = self
            .base_delay
            .saturating_mul(1u32 << exponent)
            .min(self.max_delay);
        backoff.mul_f64(1.0 - 0.25 * unit_random())
    }
}

/// `retry-after-ms` (milliseconds, may be fractional), else `retry-after` (seconds or an
/// HTTP date). A value that is negative, not a number or too long for a [`Duration`]
/// (`1e308`) counts as absent: the headers come from the server, so none of them may panic.
pub(crate) fn server_requested_delay(response: &WireResponse, now: SystemTime) -> Option<Duration> {
    if let Some(ms) = response
        .header("retry-after-ms")
        .and_then(|v| v.trim().parse::<f64>().ok())
        && let Ok(delay) = Duration::try_from_secs_f64(ms / 1e3)
    {
        return Some(delay);
    }
    let value = response.header("retry-after")?.trim();
    if let Ok(seconds) = value.parse::<f64>() {
        return Duration::try_from_secs_f64(seconds).ok();
    }
    let when = httpdate::parse_http_date(value).ok()?;
    Some(when.duration_since(now).unwrap_or(Duration::ZERO))
}

/// A uniform number in [0, 1) from the standard library's randomly keyed hasher: jitter
/// needs no cryptographic quality.
fn unit_random() -> f64 {
    let mut hasher = std::collections::hash_map::RandomState::new().build_hasher();
    hasher.write_u64(
        SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos() as u64),
    );
    (hasher.finish() >> 11) as f64 / (1u64 << 53) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transport::Origin;

    fn response(status: u16, headers: &[(&str, &str)], body: &str) -> WireResponse {
        WireResponse {
            status,
            headers: headers
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            body: body.to_string().into(),
            origin: Origin::Live,
        }
    }

    #[test]
    fn retryable_statuses() {
        let plain = ProviderError::default();
        for status in [408, 409, 429, 500, 502, 503] {
            assert!(
                status_is_retryable(&response(status, &[], ""), &plain),
                "{status}"
            );
        }
        for status in [400, 401, 403, 404, 422] {
            assert!(
                !status_is_retryable(&response(status, &[], ""), &plain),
                "{status}"
            );
        }
        let quota = ProviderError::from_body(br#"{"error":{"code":"insufficient_quota","message":"no"}}"#);
        assert!(!status_is_retryable(&response(429, &[], ""), &quota));
        assert!(!status_is_retryable(
            &response(500, &[("x-should-retry", "false")], ""),
            &plain
        ));
        assert!(status_is_retryable(
            &response(400, &[("x-should-retry", "true")], ""),
            &plain
        ));
    }

    #[test]
    fn server_delays_in_order_of_preference() {
        let now = SystemTime::UNIX_EPOCH + Duration::from_secs(1_700_000_000);
        let both = response(429, &[("retry-after", "7"), ("retry-after-ms", "1500.5")], "");
        assert_eq!(
            server_requested_delay(&both, now),
            Some(Duration::from_micros(1_500_500))
        );
        let seconds = response(429, &[("retry-after", "2")], "");
        assert_eq!(
            server_requested_delay(&seconds, now),
            Some(Duration::from_secs(2))
        );
        let date = httpdate::fmt_http_date(now + Duration::from_secs(30));
        let dated = response(429, &[("retry-after", date.as_str())], "");
        assert_eq!(server_requested_delay(&dated, now), Some(Duration::from_secs(30)));
        assert_eq!(
            server_requested_delay(&response(429, &[("retry-after", "soon")], ""), now),
            None
        );
    }

    #[test]
    fn backoff_doubles_with_jitter_and_caps() {
        let policy = RetryPolicy::default();
        for (failed, nominal) in [(1, 500), (2, 1000), (3, 2000), (6, 8000), (40, 8000)] {
            let delay = policy.delay(failed, None).as_millis() as u64;
            assert!(
                delay <= nominal && delay >= nominal * 3 / 4,
                "attempt {failed}: {delay} ms"
            );
        }
        let too_long = response(429, &[("retry-after", "600")], "");
        assert!(policy.delay(1, Some(&too_long)) <= Duration::from_millis(500));
    }

    #[test]
    fn absurd_retry_delays_fall_back_to_the_backoff() {
        let policy = RetryPolicy::default();
        let now = SystemTime::now();
        for (header, value) in [
            ("retry-after", "1e20"),
            ("retry-after", "18446744073709551616"),
            ("retry-after", "1e308"),
            ("retry-after", "-3"),
            ("retry-after", "NaN"),
            ("retry-after", "inf"),
            ("retry-after-ms", "1e308"),
            ("retry-after-ms", "-1"),
        ] {
            let reply = response(429, &[(header, value)], "");
            assert_eq!(server_requested_delay(&reply, now), None, "{header}: {value}");
            assert!(
                policy.delay(1, Some(&reply)) <= Duration::from_millis(500),
                "{header}: {value}"
            );
        }
    }
}
