//! Which frames of a sequence become the demo's keyframes.
//!
//! - `auto`: the first frame, then each frame at which the scene, having changed, has come to
//!   rest again (the paper's "semantically coherent interval": one completed action);
//! - `every:SECONDS`: the first frame and one every SECONDS after it;
//! - `at:T1,T2,...`: the frames nearest the given times (seconds from the start);
//! - `all`: every frame (a folder that already holds keyframes only).

use std::str::FromStr;

use crate::decode::Thumbnail;

/// How keyframes are chosen.
#[derive(Debug, Clone, PartialEq)]
pub enum KeyframeMode {
    /// Every frame is a keyframe.
    All,
    /// Motion that comes to rest, found in the pictures.
    Auto,
    /// One keyframe every this many seconds, from the first frame.
    Every(f64),
    /// The frames nearest these times (seconds, increasing).
    At(Vec<f64>),
}

impl KeyframeMode {
    /// The mode's name as the command line writes it.
    pub fn label(&self) -> String {
        match self {
            KeyframeMode::All => "all".into(),
            KeyframeMode::Auto => "auto".into(),
            KeyframeMode::Every(s) => format!("every:{s}"),
            KeyframeMode::At(times) => {
                format!(
                    "at:{}",
                    times.iter().map(|t| t.to_string()).collect::<Vec<_>>().join(",")
                )
            }
        }
    }
}

impl FromStr for KeyframeMode {
    type Err = String;

    /// `all`, `auto`, `every:SECONDS` or `at:T1,T2,...`.
    ///
    /// ```
    /// use nesy_import::KeyframeMode;
    ///
    /// assert_eq!("every:2.5".parse::<KeyframeMode>().unwrap(), KeyframeMode::Every(2.5));
    /// assert_eq!("at:0,1.5,4".parse::<KeyframeMode>().unwrap(), KeyframeMode::At(vec![0.0, 1.5, 4.0]));
    /// assert!("at:3,1".parse::<KeyframeMode>().unwrap_err().contains("increasing"));
    /// ```
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let expected = "expected `auto`, `all`, `every:SECONDS` or `at:T1,T2,...`";
        match text {
            "all" => return Ok(KeyframeMode::All),
            "auto" => return Ok(KeyframeMode::Auto),
            _ => {}
        }
        let number = |s: &str| -> Result<f64, String> {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| format!("`{s}` is not a number of seconds (0 or more) in `{text}`"))
        };
        if let Some(seconds) = text.strip_prefix("every:") {
            let seconds = number(seconds)?;
            if seconds <= 0.0 {
                return Err(format!("every: needs a positive interval, got `{text}`"));
            }
            return Ok(KeyframeMode::Every(seconds));
        }
        if let Some(list) = text.strip_prefix("at:") {
            let times = list
                .split(',')
                .map(number)
                .collect::<Result<Vec<f64>, String>>()?;
            if times.windows(2).any(|w| w[1] <= w[0]) {
                return Err(format!("at: times must be increasing, got `{text}`"));
            }
            return Ok(KeyframeMode::At(times));
        }
        Err(format!("unknown keyframe mode `{text}`: {expected}"))
    }
}

/// Luma difference (0–255, over the thumbnail block where two consecutive frames differ
/// most) below which they count as still, whatever the sequence's own noise. Chosen on
/// simulated demonstration videos kept apart from the ones the keyframe figures are measured
/// on: lower values take an object still settling in the gripper for motion and miss the
/// rest that follows, higher ones miss small hand movements.
pub const MIN_MOTION: f32 = 4.0;

/// How long the pictures must stay still for the scene to count as at rest (seconds).
pub const MIN_REST_S: f64 = 0.3;

/// The two numbers `auto` is tuned by.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct AutoSettings {
    /// The least luma difference that counts as motion, whatever the sequence's noise
    /// ([`MIN_MOTION`] by default).
    pub min_motion: f32,
    /// Seconds the pictures must stay still for the scene to be at rest ([`MIN_REST_S`] by
    /// default).
    pub min_rest_s: f64,
}

impl Default for AutoSettings {
    fn default() -> Self {
        AutoSettings {
            min_motion: MIN_MOTION,
            min_rest_s: MIN_REST_S,
        }
    }
}

impl AutoSettings {
    /// Checks both numbers, saying which is wrong.
    pub fn check(&self) -> Result<(), String> {
        if !(self.min_motion.is_finite() && (0.0..=255.0).contains(&self.min_motion)) {
            return Err(format!(
                "the least motion must be a luma difference from 0 to 255, got {}",
                self.min_motion
            ));
        }
        if !(self.min_rest_s.is_finite() && self.min_rest_s >= 0.0) {
            return Err(format!(
                "the rest must be 0 seconds or more, got {}",
                self.min_rest_s
            ));
        }
        Ok(())
    }
}

/// What `auto` measured: the threshold it used and each frame's difference to the one before.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MotionTrace {
    /// Luma difference above which a frame counts as moving.
    pub threshold: f32,
    /// Difference of each frame to the previous one (0 for the first).
    pub differences: Vec<f32>,
}

/// The frames (indices into `times`) chosen as keyframes. `thumbnails[i]` holds frame `i`'s
/// views (only `auto` reads them). The first frame is always a keyframe.
pub fn select(
    mode: &KeyframeMode,
    times: &[f64],
    thumbnails: &[Vec<Thumbnail>],
    settings: &AutoSettings,
) -> Result<Vec<usize>, String> {
    if times.is_empty() {
        return Err("the sequence has no frames".into());
    }
    let duration = times[times.len() - 1];
    let nearest = |t: f64| -> usize {
        let after = times.partition_point(|&x| x < t).min(times.len() - 1);
        if after > 0 && (t - times[after - 1]).abs() <= (times[after] - t).abs() {
            after - 1
        } else {
            after
        }
    };
    let chosen = match mode {
        KeyframeMode::All => (0..times.len()).collect(),
        KeyframeMode::Every(step) => {
            let mut chosen = Vec::new();
            let mut k = 0.0;
            while k * step <= duration + 1e-9 {
                chosen.push(nearest(k * step));
                k += 1.0;
            }
            chosen
        }
        KeyframeMode::At(at) => {
            let frame = if times.len() > 1 { times[1] - times[0] } else { 0.0 };
            if let Some(late) = at.iter().find(|&&t| t > duration + frame) {
                return Err(format!(
                    "at: {late} s is after the end of the sequence ({duration:.3} s)"
                ));
            }
            at.iter().map(|&t| nearest(t)).collect()
        }
        KeyframeMode::Auto => detect(times, thumbnails, settings)?.0,
    };
    let mut unique: Vec<usize> = Vec::with_capacity(chosen.len());
    for i in chosen {
        if unique.last() == Some(&i) {
            return Err(format!(
                "two keyframe times fall on the same frame ({:.3} s); the frames are {:.3} s apart",
                times[i],
                if times.len() > 1 { times[1] - times[0] } else { 0.0 }
            ));
        }
        unique.push(i);
    }
    Ok(unique)
}

/// `auto`: the keyframes and what was measured to find them.
///
/// A frame moves when its difference to the frame before (the largest over its views)
/// exceeds the threshold: three times the sequence's quiet level (its 20th-percentile
/// difference, the sensor noise of a real camera) and at least `settings.min_motion`. After
/// motion, the first frame of a still stretch (frames that match the one before) lasting
/// `settings.min_rest_s` is a keyframe, when it differs
/// from the keyframe before by more than the threshold (motion that put everything back, such
/// as a hand passing through, is not an action). Motion still going at the end closes with
/// the last frame.
pub fn detect(
    times: &[f64],
    thumbnails: &[Vec<Thumbnail>],
    settings: &AutoSettings,
) -> Result<(Vec<usize>, MotionTrace), String> {
    settings.check()?;
    if thumbnails.len() != times.len() {
        return Err(format!(
            "{} frame times but {} pictures",
            times.len(),
            thumbnails.len()
        ));
    }
    let compare = |a: usize, b: usize| -> Result<f32, String> {
        let mut largest = 0.0f32;
        for (x, y) in thumbnails[a].iter().zip(&thumbnails[b]) {
            let d = x
                .difference(y)
                .ok_or_else(|| format!("frames {a} and {b} of one view differ in size"))?;
            largest = largest.max(d);
        }
        Ok(largest)
    };
    let mut differences = vec![0.0f32; times.len()];
    for (i, difference) in differences.iter_mut().enumerate().skip(1) {
        *difference = compare(i, i - 1)?;
    }
    let mut sorted: Vec<f32> = differences.iter().skip(1).copied().collect();
    sorted.sort_by(f32::total_cmp);
    let quiet = sorted.get(sorted.len() / 5).copied().unwrap_or(0.0);
    let threshold = (3.0 * quiet).max(settings.min_motion);

    let mut chosen = vec![0];
    let mut moved = false;
    let mut rest_start: Option<usize> = None;
    for i in 1..times.len() {
        if differences[i] > threshold {
            moved = true;
            rest_start = None;
            continue;
        }
        // Frame i matches frame i - 1: the still stretch began at i - 1, the first frame that
        // shows the scene as it now rests.
        let first = *rest_start.get_or_insert(i - 1);
        let rested = times[i] - times[first] >= settings.min_rest_s - 1e-9;
        if moved && rested {
            let last = chosen[chosen.len() - 1];
            if compare(first, last)? > threshold {
                chosen.push(first);
            }
            moved = false;
        }
    }
    let last = times.len() - 1;
    if moved && chosen[chosen.len() - 1] != last && compare(last, chosen[chosen.len() - 1])? > threshold {
        chosen.push(last);
    }
    Ok((
        chosen,
        MotionTrace {
            threshold,
            differences,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A one-view thumbnail whose pixels all have `level`, with a little per-frame noise.
    fn flat(level: f32, noise: f32) -> Vec<Thumbnail> {
        vec![Thumbnail {
            width: 4,
            height: 4,
            luma: (0..16)
                .map(|i| level + if i % 2 == 0 { noise } else { -noise })
                .collect(),
        }]
    }

    /// 10 fps: still, a move to a new level, still, a move and back, still, a final move.
    fn sequence() -> (Vec<f64>, Vec<Vec<Thumbnail>>) {
        let mut levels = Vec::new();
        levels.extend([10.0; 10]); // 0.0–0.9 s at rest
        levels.extend([20.0, 30.0, 40.0, 50.0]); // moving
        levels.extend([60.0; 10]); // at rest from 1.4 s
        levels.extend([80.0, 100.0, 80.0]); // a hand passes
        levels.extend([60.0; 10]); // the same scene again
        levels.extend([70.0, 90.0]); // moving at the end
        let times = (0..levels.len()).map(|i| i as f64 / 10.0).collect();
        let thumbnails = levels
            .iter()
            .enumerate()
            .map(|(i, &l)| flat(l, if i % 2 == 0 { 0.2 } else { -0.2 }))
            .collect();
        (times, thumbnails)
    }

    #[test]
    fn auto_finds_rest_after_change_and_ignores_a_passing_hand() {
        let (times, thumbnails) = sequence();
        let (chosen, trace) = detect(&times, &thumbnails, &AutoSettings::default()).unwrap();
        assert_eq!(chosen, [0, 14, 38]);
        assert!(trace.threshold >= MIN_MOTION);
    }

    #[test]
    fn manual_modes_pick_the_nearest_frames() {
        let (times, thumbnails) = sequence();
        assert_eq!(
            select(
                &KeyframeMode::Every(1.0),
                &times,
                &thumbnails,
                &AutoSettings::default()
            )
            .unwrap(),
            [0, 10, 20, 30]
        );
        assert_eq!(
            select(
                &KeyframeMode::At(vec![0.0, 1.44, 2.0]),
                &times,
                &thumbnails,
                &AutoSettings::default()
            )
            .unwrap(),
            [0, 14, 20]
        );
        assert!(
            select(
                &KeyframeMode::At(vec![0.0, 9.0]),
                &times,
                &thumbnails,
                &AutoSettings::default()
            )
            .unwrap_err()
            .contains("after the end")
        );
        assert!(
            select(
                &KeyframeMode::At(vec![1.0, 1.01]),
                &times,
                &thumbnails,
                &AutoSettings::default()
            )
            .unwrap_err()
            .contains("same frame")
        );
        assert_eq!(
            select(
                &KeyframeMode::All,
                &times[..3],
                &thumbnails[..3],
                &AutoSettings::default()
            )
            .unwrap(),
            [0, 1, 2]
        );
    }

    #[test]
    fn modes_parse_and_label_themselves() {
        for text in ["auto", "all", "every:0.5", "at:0,1.5,4"] {
            assert_eq!(text.parse::<KeyframeMode>().unwrap().label(), text);
        }
        for bad in ["sometimes", "every:0", "every:-1", "at:", "at:1,x", "every:nan"] {
            assert!(bad.parse::<KeyframeMode>().is_err(), "{bad}");
        }
    }
}

/// Seconds within which a chosen keyframe counts as finding a true one.
pub const MATCH_TOLERANCE_S: f64 = 0.5;

/// How chosen keyframes compare with the true ones of a recording.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct KeyframeMatch {
    /// Seconds within which a chosen keyframe finds a true one.
    pub tolerance_s: f64,
    /// True keyframes.
    pub truth: usize,
    /// Chosen keyframes.
    pub chosen: usize,
    /// Pairs matched one to one.
    pub matched: usize,
    /// The true keyframes' times that no chosen keyframe found.
    pub missed: Vec<f64>,
    /// The chosen keyframes' times that found no true one.
    pub extra: Vec<f64>,
    /// The matched pairs: (true keyframe, chosen keyframe), positions in the two lists.
    pub pairs: Vec<(usize, usize)>,
}

impl KeyframeMatch {
    /// Matched true keyframes over true keyframes.
    pub fn recall(&self) -> f64 {
        self.matched as f64 / self.truth.max(1) as f64
    }

    /// Matched chosen keyframes over chosen keyframes.
    pub fn precision(&self) -> f64 {
        self.matched as f64 / self.chosen.max(1) as f64
    }
}

/// Matches `chosen` keyframe times with `truth` (both increasing) one to one within
/// `tolerance` seconds, in time order: a chosen time too early for the next true one is
/// extra, a true time that the next chosen one is too late for is missed.
///
/// ```
/// use nesy_import::match_keyframes;
///
/// let m = match_keyframes(&[0.0, 2.0, 5.0], &[0.0, 2.3, 3.5], 0.5);
/// assert_eq!((m.matched, m.missed.clone(), m.extra.clone()), (2, vec![5.0], vec![3.5]));
/// ```
pub fn match_keyframes(truth: &[f64], chosen: &[f64], tolerance: f64) -> KeyframeMatch {
    let (mut i, mut j) = (0, 0);
    let (mut missed, mut extra, mut pairs) = (Vec::new(), Vec::new(), Vec::new());
    while i < truth.len() && j < chosen.len() {
        if chosen[j] < truth[i] - tolerance {
            extra.push(chosen[j]);
            j += 1;
        } else if chosen[j] > truth[i] + tolerance {
            missed.push(truth[i]);
            i += 1;
        } else {
            pairs.push((i, j));
            i += 1;
            j += 1;
        }
    }
    missed.extend_from_slice(&truth[i..]);
    extra.extend_from_slice(&chosen[j..]);
    KeyframeMatch {
        tolerance_s: tolerance,
        truth: truth.len(),
        chosen: chosen.len(),
        matched: pairs.len(),
        missed,
        extra,
        pairs,
    }
}
