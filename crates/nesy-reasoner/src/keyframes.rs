//! Where the reasoner's images come from: the pipeline implements [`KeyframeImages`] over
//! whatever holds the demonstration (an MCAP file, a folder of PNGs, a live simulator), so
//! the reasoner needs no knowledge of those formats.

use nesy_vlm::{Image, Part};

/// The three labelled ("marked") camera views of one scene state.
#[derive(Debug, Clone, PartialEq)]
pub struct Views {
    /// The top view.
    pub top: Image,
    /// The front view (looking at the robot).
    pub front: Image,
    /// The back view (from behind the robot).
    pub back: Image,
}

impl Views {
    /// The views with their names, in prompt order: top, front, back.
    pub fn named(&self) -> [(&'static str, &Image); 3] {
        [("top", &self.top), ("front", &self.front), ("back", &self.back)]
    }

    /// Message parts: a short text label before each image, e.g. `Before the action, top
    /// view:`.
    pub fn parts(&self, caption: &str) -> Vec<Part> {
        let mut parts = Vec::with_capacity(6);
        for (name, image) in self.named() {
            parts.push(Part::text(format!("{caption}, {name} view:")));
            parts.push(Part::Image(image.clone()));
        }
        parts
    }
}

/// The demonstration's keyframes as the reasoner sees them.
///
/// Keyframe `k` is the state `s_k` (0-based; keyframe 0 is the state after reset).
/// Transition `t` goes from keyframe `t` to keyframe `t + 1`, as in nesy-core's
/// [`InductionRequest::step`](nesy_core::adapt::InductionRequest).
pub trait KeyframeImages: Send + Sync {
    /// The marked top/front/back views of keyframe `keyframe`, or `None` when the
    /// demonstration has no images for it (the request is then sent without images).
    fn views(&self, keyframe: usize) -> Option<Views>;
}

/// A demonstration without images: requests are text-only.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoKeyframes;

impl KeyframeImages for NoKeyframes {
    fn views(&self, _keyframe: usize) -> Option<Views> {
        None
    }
}

/// Keyframes held in memory: one [`Views`] per keyframe.
#[derive(Debug, Clone, Default)]
pub struct KeyframeList {
    /// Views by keyframe index.
    pub views: Vec<Views>,
}

impl KeyframeImages for KeyframeList {
    fn views(&self, keyframe: usize) -> Option<Views> {
        self.views.get(keyframe).cloned()
    }
}
