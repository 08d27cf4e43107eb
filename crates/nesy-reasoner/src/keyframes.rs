//! Where the reasoner's images come from: the pipeline implements [`KeyframeImages`] over
//! whatever holds the demonstration (an MCAP file, a folder of PNGs, a live simulator), so
//! the reasoner needs no knowledge of those formats.

use nesy_vlm::{Image, Part};

/// The camera views of one scene state, each under its name, in the order prompts show
/// them: the simulator's top, front and back, or a real demonstration's own views (one
/// camera or several, named as the user named them).
#[derive(Debug, Clone, PartialEq)]
pub struct Views {
    views: Vec<(String, Image)>,
}

impl Views {
    /// Views from `(name, image)` pairs, in prompt order.
    ///
    /// ```
    /// use nesy_reasoner::Views;
    /// use nesy_vlm::Image;
    ///
    /// let png = |seed| Image::png(nesy_testkit::png(4, seed)).unwrap();
    /// let views = Views::new([("top", png(1)), ("wrist", png(2))]);
    /// assert_eq!(views.names().collect::<Vec<_>>(), ["top", "wrist"]);
    /// assert_eq!(views.parts("Before the action").len(), 4);
    /// ```
    pub fn new<N: Into<String>>(views: impl IntoIterator<Item = (N, Image)>) -> Views {
        Views {
            views: views.into_iter().map(|(n, i)| (n.into(), i)).collect(),
        }
    }

    /// The views with their names, in prompt order.
    pub fn named(&self) -> impl Iterator<Item = (&str, &Image)> {
        self.views.iter().map(|(n, i)| (n.as_str(), i))
    }

    /// The view names, in prompt order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.views.iter().map(|(n, _)| n.as_str())
    }

    /// How many views there are.
    pub fn len(&self) -> usize {
        self.views.len()
    }

    /// True when there is no view.
    pub fn is_empty(&self) -> bool {
        self.views.is_empty()
    }

    /// Message parts: a short text label before each image, e.g. `Before the action, top
    /// view:`.
    pub fn parts(&self, caption: &str) -> Vec<Part> {
        let mut parts = Vec::with_capacity(2 * self.views.len());
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
