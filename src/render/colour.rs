//! Colours of bodies: a perceptual colour map ([`ColourMap`]) and the mapping of one scalar per body to a colour
//! ([`ColourScale`]): continuous (clamped to [min, max] through the map) or categorical (a few named values, e.g.
//! bound = 1 / unbound = 0, each with its own colour).

/// A colour map from [0, 1] to RGB.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColourMap {
    /// Viridis (van der Walt & Smith, matplotlib 1.5): perceptually uniform, readable in grey and by colour-blind
    /// viewers; dark purple at 0, green in the middle, yellow at 1.
    #[default]
    Viridis,
}

/// Viridis at t = 0, 1/8, …, 1 (the published 9-step samples); linear interpolation between them stays within a
/// few RGB levels of the full table.
const VIRIDIS_ANCHORS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [72, 40, 120],
    [62, 73, 137],
    [49, 104, 142],
    [38, 130, 142],
    [31, 158, 137],
    [53, 183, 121],
    [110, 206, 88],
    [253, 231, 37],
];

impl ColourMap {
    /// The colour at `t` (clamped to [0, 1]; NaN gives the colour at 0).
    pub fn colour(self, t: f64) -> [u8; 3] {
        let anchors = match self {
            ColourMap::Viridis => &VIRIDIS_ANCHORS,
        };
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let pos = t * (anchors.len() - 1) as f64;
        let i = (pos.floor() as usize).min(anchors.len() - 2);
        let f = pos - i as f64;
        let (a, b) = (anchors[i], anchors[i + 1]);
        std::array::from_fn(|k| (f64::from(a[k]) + f * (f64::from(b[k]) - f64::from(a[k]))).round() as u8)
    }
}

/// Distinct colours for categories, in order: orange, blue, green, red, purple, grey. Chosen to read on the dark
/// frame background and to stay apart from each other.
const CATEGORY_COLOURS: [[u8; 3]; 6] = [
    [240, 150, 40],
    [70, 140, 230],
    [90, 190, 90],
    [220, 70, 70],
    [170, 120, 210],
    [170, 170, 170],
];

/// Colour of values a scale cannot place (NaN): neutral grey.
pub const MISSING_COLOUR: [u8; 3] = [128, 128, 128];

/// One named value of a categorical scale.
#[derive(Clone, Debug, PartialEq)]
pub struct Category {
    /// The value that selects this category (a body's value picks the nearest category).
    pub value: f64,
    /// Name shown on the colour bar.
    pub name: String,
    /// Colour of the category.
    pub colour: [u8; 3],
}

/// Continuous or categorical.
#[derive(Clone, Debug, PartialEq)]
pub enum ScaleKind {
    /// Values from `min` to `max` through a colour map; values outside are clamped.
    Continuous {
        /// Value drawn at the bottom of the bar (same unit as the values).
        min: f64,
        /// Value drawn at the top of the bar.
        max: f64,
        /// The colour map.
        map: ColourMap,
    },
    /// A few named values, each with its own colour.
    Categorical(Vec<Category>),
}

/// How one scalar per body becomes a colour, with the label of the colour bar.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourScale {
    /// Label of the colour bar (quantity and unit, e.g. "speed (m/s)").
    pub label: String,
    /// Continuous or categorical mapping.
    pub kind: ScaleKind,
}

impl ColourScale {
    /// A continuous viridis scale from `min` to `max`.
    pub fn new(label: impl Into<String>, min: f64, max: f64) -> ColourScale {
        ColourScale {
            label: label.into(),
            kind: ScaleKind::Continuous {
                min,
                max,
                map: ColourMap::Viridis,
            },
        }
    }

    /// A continuous viridis scale over the finite values of `values` (0 to 1 when there are none).
    pub fn spanning(label: impl Into<String>, values: impl IntoIterator<Item = f64>) -> ColourScale {
        let (lo, hi) = values
            .into_iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        if lo <= hi {
            ColourScale::new(label, lo, hi)
        } else {
            ColourScale::new(label, 0.0, 1.0)
        }
    }

    /// A categorical scale: each `(value, name)` gets the next of a fixed set of distinct colours (they repeat
    /// after six). For a two-valued field: `categorical("bound", vec![(1.0, "bound".into()), (0.0, "free".into())])`.
    pub fn categorical(label: impl Into<String>, names: Vec<(f64, String)>) -> ColourScale {
        let categories = names
            .into_iter()
            .enumerate()
            .map(|(i, (value, name))| Category {
                value,
                name,
                colour: CATEGORY_COLOURS[i % CATEGORY_COLOURS.len()],
            })
            .collect();
        ColourScale {
            label: label.into(),
            kind: ScaleKind::Categorical(categories),
        }
    }

    /// The colour of `value`: continuous, the map's colour at `value` mapped linearly from [min, max] to [0, 1]
    /// (clamped; the middle when `max == min`); categorical, the nearest category's. NaN (or an empty categorical
    /// scale) gives [`MISSING_COLOUR`].
    pub fn colour(&self, value: f64) -> [u8; 3] {
        match &self.kind {
            ScaleKind::Continuous { .. } if value.is_nan() => MISSING_COLOUR,
            ScaleKind::Continuous { min, max, map } if max > min => {
                map.colour(((value - min) / (max - min)).clamp(0.0, 1.0))
            }
            ScaleKind::Continuous { map, .. } => map.colour(0.5),
            ScaleKind::Categorical(categories) => {
                nearest(categories, value).map_or(MISSING_COLOUR, |i| categories[i].colour)
            }
        }
    }
}

/// Index of the category whose value is nearest to `value`; `None` for NaN or no categories.
fn nearest(categories: &[Category], value: f64) -> Option<usize> {
    if value.is_nan() {
        return None;
    }
    categories
        .iter()
        .enumerate()
        .min_by(|(_, a), (_, b)| (a.value - value).abs().total_cmp(&(b.value - value).abs()))
        .map(|(i, _)| i)
}
