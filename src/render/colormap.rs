//! Colormaps: piecewise-linear maps from [0, 1] to sRGB, with our own control points.

/// A colormap for per-triangle scalars.
///
/// Both maps are piecewise linear between five control points chosen so that lightness changes
/// monotonically (sequential) or symmetrically about the middle (diverging), which keeps equal
/// steps of the scalar roughly equally visible.
///
/// # Examples
///
/// ```
/// use topomech::render::Colormap;
///
/// assert_eq!(Colormap::default(), Colormap::Sequential);
/// let (seq, div) = (Colormap::Sequential, Colormap::Diverging);
/// assert_ne!(seq.color(0.0), seq.color(1.0));
/// assert_eq!(div.color(0.5), div.color(f64::NAN)); // NaN maps to the middle
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Colormap {
    /// Dark blue-violet → teal → green → yellow: for magnitudes (stress, level).
    #[default]
    Sequential,
    /// Blue → light grey → red: for signed quantities (compression / tension).
    Diverging,
}

const SEQUENTIAL: [[u8; 3]; 5] = [[48, 26, 96], [42, 88, 152], [30, 148, 140], [118, 196, 84], [246, 226, 52]];
const DIVERGING: [[u8; 3]; 5] = [[44, 72, 168], [124, 160, 222], [232, 232, 228], [228, 140, 100], [164, 28, 40]];

impl Colormap {
    /// The colour of `t`, clamped to [0, 1] (NaN gives the middle colour). O(1).
    ///
    /// ```
    /// use topomech::render::Colormap;
    ///
    /// let m = Colormap::Diverging;
    /// assert_eq!(m.color(-3.0), m.color(0.0)); // clamped
    /// assert_ne!(m.color(0.0), m.color(1.0));
    /// ```
    pub fn color(self, t: f64) -> [u8; 3] {
        let points = match self {
            Colormap::Sequential => &SEQUENTIAL,
            Colormap::Diverging => &DIVERGING,
        };
        let t = if t.is_nan() { 0.5 } else { t.clamp(0.0, 1.0) };
        let x = t * (points.len() - 1) as f64;
        let i = (x.floor() as usize).min(points.len() - 2);
        let f = x - i as f64;
        let (a, b) = (points[i], points[i + 1]);
        std::array::from_fn(|k| (a[k] as f64 + f * (b[k] as f64 - a[k] as f64)).round() as u8)
    }

    /// The colour of `value` on the scale `lo..=hi` (the middle colour when `lo == hi`), i.e. of
    /// `t = (value − lo) / (hi − lo)`, for any finite ends: when `hi − lo` is past f64::MAX
    /// (e.g. `-1e308..=1e308`) both differences are taken of halves, which is exact save in the
    /// subnormal range. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::render::Colormap;
    ///
    /// let m = Colormap::Sequential;
    /// assert_eq!(m.color_in(15.0, 10.0, 20.0), m.color(0.5));
    /// assert_eq!(m.color_in(99.0, 10.0, 20.0), m.color(1.0)); // clamped
    /// assert_eq!(m.color_in(3.0, 4.0, 4.0), m.color(0.5)); // empty scale: the middle colour
    /// assert_eq!(m.color_in(0.0, -f64::MAX, f64::MAX), m.color(0.5)); // a span past f64::MAX
    /// ```
    pub fn color_in(self, value: f64, lo: f64, hi: f64) -> [u8; 3] {
        if hi <= lo || hi.is_nan() || lo.is_nan() {
            return self.color(0.5);
        }
        let span = hi - lo;
        let t = if span.is_finite() { (value - lo) / span } else { (value / 2.0 - lo / 2.0) / (hi / 2.0 - lo / 2.0) };
        self.color(t)
    }
}
