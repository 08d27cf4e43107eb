//! Per-call usage, latency and attempts, aggregated per run, with optional cost.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::response::Usage;
use crate::transport::Origin;

/// Prices of one model in US dollars per million tokens.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelPrice {
    /// Uncached input tokens.
    pub input_per_mtok: f64,
    /// Cached input tokens (defaults to the input price).
    #[serde(default)]
    pub cached_input_per_mtok: Option<f64>,
    /// Output tokens, reasoning included.
    pub output_per_mtok: f64,
}

/// Prices by model name. A model matches its exact entry, else the longest entry that is a
/// prefix of it (`gpt-5` prices `gpt-5-2025-08-07`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct PriceTable(pub BTreeMap<String, ModelPrice>);

impl PriceTable {
    /// The price entry for a model, if any.
    pub fn lookup(&self, model: &str) -> Option<&ModelPrice> {
        self.0.get(model).or_else(|| {
            self.0
                .iter()
                .filter(|(prefix, _)| model.starts_with(prefix.as_str()))
                .max_by_key(|(prefix, _)| prefix.len())
                .map(|(_, price)| price)
        })
    }

    /// The cost of a call in US dollars, if the model is priced.
    pub fn cost(&self, model: &str, usage: &Usage) -> Option<f64> {
        let price = self.lookup(model)?;
        let cached = usage.cached_prompt_tokens.min(usage.prompt_tokens);
        let uncached = usage.prompt_tokens - cached;
        let cached_price = price.cached_input_per_mtok.unwrap_or(price.input_per_mtok);
        Some(
            (uncached as f64 * price.input_per_mtok
                + cached as f64 * cached_price
                + usage.completion_tokens as f64 * price.output_per_mtok)
                / 1e6,
        )
    }
}

/// One finished call (successful or not), as accounting sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct CallRecord {
    /// The model named in the request.
    pub model: String,
    /// The accounting label of the request.
    pub purpose: Option<String>,
    /// Usage, when known (failed calls that got a body may still have it).
    pub usage: Option<Usage>,
    /// When the call began (before it waited for a concurrency slot).
    pub started: Instant,
    /// Wall time, retries included.
    pub latency: Duration,
    /// Attempts made.
    pub attempts: u32,
    /// Where the final answer came from (`None` when no response arrived).
    pub origin: Option<Origin>,
    /// Whether the call returned `Ok`.
    pub succeeded: bool,
}

/// Totals over a group of calls.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct UsageTotals {
    /// Calls made.
    pub calls: u64,
    /// Calls that ended in an error.
    pub failed_calls: u64,
    /// Calls answered by a live server.
    pub live_calls: u64,
    /// Calls answered from a cassette.
    pub replayed_calls: u64,
    /// Calls answered by an offline responder.
    pub offline_calls: u64,
    /// Attempts over all calls (retries = attempts − calls).
    pub attempts: u64,
    /// Input tokens.
    pub prompt_tokens: u64,
    /// Output tokens, reasoning included.
    pub completion_tokens: u64,
    /// Reasoning tokens.
    pub reasoning_tokens: u64,
    /// Cached input tokens.
    pub cached_prompt_tokens: u64,
    /// Calls whose server reported no usage.
    pub calls_without_usage: u64,
    /// Summed wall time in milliseconds: calls in flight together each count in full.
    pub latency_ms_total: f64,
    /// Wall time in milliseconds during which at least one of these calls was in flight:
    /// the time spent waiting for answers, which concurrent calls share rather than add up.
    #[serde(default)]
    pub waiting_ms_total: f64,
    /// The calls' intervals behind `waiting_ms_total`, merged and in order.
    #[serde(skip)]
    in_flight: Vec<(Instant, Instant)>,
    /// Slowest call in milliseconds.
    pub latency_ms_max: f64,
    /// Cost in US dollars of the priced calls (replayed calls included: they cost this when
    /// recorded).
    pub cost_usd: f64,
    /// Calls whose model has no price entry.
    pub unpriced_calls: u64,
}

impl UsageTotals {
    fn add(&mut self, record: &CallRecord, cost: Option<f64>) {
        self.calls += 1;
        self.failed_calls += u64::from(!record.succeeded);
        match record.origin {
            Some(Origin::Live) => self.live_calls += 1,
            Some(Origin::Replayed) => self.replayed_calls += 1,
            Some(Origin::Offline) => self.offline_calls += 1,
            None => {}
        }
        self.attempts += u64::from(record.attempts);
        match &record.usage {
            Some(usage) => {
                self.prompt_tokens += usage.prompt_tokens;
                self.completion_tokens += usage.completion_tokens;
                self.reasoning_tokens += usage.reasoning_tokens;
                self.cached_prompt_tokens += usage.cached_prompt_tokens;
            }
            None => self.calls_without_usage += 1,
        }
        let ms = record.latency.as_secs_f64() * 1e3;
        self.latency_ms_total += ms;
        self.add_in_flight(record.started, record.started + record.latency);
        self.latency_ms_max = self.latency_ms_max.max(ms);
        match cost {
            Some(cost) => self.cost_usd += cost,
            None if record.usage.is_some() => self.unpriced_calls += 1,
            None => {}
        }
    }

    /// Adds the interval `[start, end)` to the merged intervals and the waiting time.
    fn add_in_flight(&mut self, start: Instant, end: Instant) {
        // The merged intervals are disjoint and sorted, so those the new one touches are
        // consecutive: the first ending at or after `start` up to the last starting by `end`.
        let first = self.in_flight.partition_point(|&(_, e)| e < start);
        let last = self.in_flight.partition_point(|&(s, _)| s <= end);
        let (mut merged_start, mut merged_end) = (start, end);
        let mut replaced = Duration::ZERO;
        for &(s, e) in &self.in_flight[first..last] {
            merged_start = merged_start.min(s);
            merged_end = merged_end.max(e);
            replaced += e - s;
        }
        self.in_flight.splice(first..last, [(merged_start, merged_end)]);
        let added = (merged_end - merged_start).saturating_sub(replaced);
        self.waiting_ms_total += added.as_secs_f64() * 1e3;
    }
}

/// Usage of a whole run: totals, and the same by model and by purpose.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RunUsage {
    /// Over all calls.
    pub total: UsageTotals,
    /// By requested model.
    pub by_model: BTreeMap<String, UsageTotals>,
    /// By purpose label (`"-"` for unlabelled calls).
    pub by_purpose: BTreeMap<String, UsageTotals>,
}

impl RunUsage {
    /// Adds one call, priced with `prices`.
    pub fn record(&mut self, record: &CallRecord, prices: &PriceTable) {
        let cost = record
            .usage
            .as_ref()
            .and_then(|usage| prices.cost(&record.model, usage));
        self.total.add(record, cost);
        self.by_model
            .entry(record.model.clone())
            .or_default()
            .add(record, cost);
        let purpose = record.purpose.clone().unwrap_or_else(|| "-".to_string());
        self.by_purpose.entry(purpose).or_default().add(record, cost);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prices_match_by_longest_prefix_and_cached_tokens_are_cheaper() {
        let mut table = PriceTable::default();
        table.0.insert(
            "gpt-5".into(),
            ModelPrice {
                input_per_mtok: 1.0,
                cached_input_per_mtok: Some(0.1),
                output_per_mtok: 10.0,
            },
        );
        table.0.insert(
            "gpt-5-mini".into(),
            ModelPrice {
                input_per_mtok: 0.5,
                cached_input_per_mtok: None,
                output_per_mtok: 2.0,
            },
        );
        let usage = Usage {
            prompt_tokens: 1_000_000,
            completion_tokens: 100_000,
            reasoning_tokens: 50_000,
            cached_prompt_tokens: 500_000,
        };
        let cost = table.cost("gpt-5-2025-08-07", &usage).unwrap();
        assert!((cost - (0.5 + 0.05 + 1.0)).abs() < 1e-9, "{cost}");
        let mini = table.cost("gpt-5-mini-2025", &usage).unwrap();
        assert!((mini - (0.5 + 0.2)).abs() < 1e-9, "{mini}");
        assert_eq!(table.cost("qwen", &usage), None);
    }

    #[test]
    fn run_usage_groups_calls() {
        let mut run = RunUsage::default();
        let prices = PriceTable::default();
        let usage = Usage {
            prompt_tokens: 10,
            completion_tokens: 5,
            reasoning_tokens: 2,
            cached_prompt_tokens: 0,
        };
        let call = |purpose: &str, attempts, origin, ok| CallRecord {
            model: "m".into(),
            purpose: Some(purpose.into()),
            usage: Some(usage),
            started: Instant::now(),
            latency: Duration::from_millis(20),
            attempts,
            origin: Some(origin),
            succeeded: ok,
        };
        run.record(&call("induce", 1, Origin::Live, true), &prices);
        run.record(&call("induce", 3, Origin::Replayed, true), &prices);
        run.record(&call("patch", 1, Origin::Live, false), &prices);
        assert_eq!(run.total.calls, 3);
        assert_eq!(run.total.attempts, 5);
        assert_eq!(run.total.failed_calls, 1);
        assert_eq!(run.total.replayed_calls, 1);
        assert_eq!(run.total.prompt_tokens, 30);
        assert_eq!(run.total.unpriced_calls, 3);
        assert_eq!(run.by_purpose["induce"].calls, 2);
        assert!((run.total.latency_ms_total - 60.0).abs() < 1e-6);
    }

    #[test]
    fn calls_in_flight_together_share_their_waiting_time() {
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        let mut totals = UsageTotals::default();
        // Recorded as they complete: [0, 100) and [10, 30) overlap, [200, 250) stands
        // alone, and [90, 210) bridges the gap between them.
        for (start, end, waiting) in [
            (10, 30, 20.0),
            (0, 100, 100.0),
            (200, 250, 150.0),
            (90, 210, 250.0),
        ] {
            totals.add_in_flight(at(start), at(end));
            assert!((totals.waiting_ms_total - waiting).abs() < 1e-6, "{totals:?}");
        }
        assert_eq!(totals.in_flight, [(at(0), at(250))]);
    }
}
