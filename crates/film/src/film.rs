//! Accumulation: rectangles, tiles, f64 layers, the film and per-thread tile buffers.

use crate::Image;

/// A half-open pixel rectangle `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Rect {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

impl Rect {
    /// The rectangle `[x0, x1) x [y0, y1)`. Panics if `x1 < x0` or `y1 < y0`.
    pub fn new(x0: usize, y0: usize, x1: usize, y1: usize) -> Self {
        assert!(x0 <= x1 && y0 <= y1, "Rect::new: inverted rectangle");
        Self { x0, y0, x1, y1 }
    }

    /// The whole `width x height` image.
    pub fn full(width: usize, height: usize) -> Self {
        Self::new(0, 0, width, height)
    }

    pub fn width(&self) -> usize {
        self.x1 - self.x0
    }

    pub fn height(&self) -> usize {
        self.y1 - self.y0
    }

    /// Number of pixels.
    pub fn area(&self) -> usize {
        self.width() * self.height()
    }

    pub fn contains(&self, x: usize, y: usize) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    fn inside(&self, width: usize, height: usize) -> bool {
        self.x1 <= width && self.y1 <= height
    }
}

/// Splits a `width x height` image into `tile_size`-square tiles (smaller at the right and
/// bottom edges), in row-major order. The tiles partition the image: every pixel is in
/// exactly one tile, which is what makes [`Film::merge_tile`] order independent.
///
/// # Panics
/// If `tile_size == 0`.
pub fn tiles(width: usize, height: usize, tile_size: usize) -> Vec<Rect> {
    assert!(tile_size > 0, "tiles: tile_size must be positive");
    let mut out = Vec::new();
    for y0 in (0..height).step_by(tile_size) {
        for x0 in (0..width).step_by(tile_size) {
            out.push(Rect::new(
                x0,
                y0,
                (x0 + tile_size).min(width),
                (y0 + tile_size).min(height),
            ));
        }
    }
    out
}

/// How [`Layer::resolve`] turns sums into pixel values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Normalize {
    /// Divide each pixel's sum by its own accumulated weight (pixels of weight 0 give 0).
    /// For path tracing with per-pixel sample counts or filter weights.
    Weight,
    /// Divide every pixel by the same number: samples per pixel, or the number of emitted
    /// photon paths for a photon-map estimate. `Constant(1.0)` returns the raw sums.
    Constant(f64),
}

/// Per-pixel f64 RGB sums and f64 weights over a rectangle. Coordinates passed to the
/// accessors are always *image* coordinates, also for a tile's layers.
///
/// Out-of-rectangle coordinates panic, like slice indexing: they are caller bugs.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    rect: Rect,
    sum: Vec<[f64; 3]>,
    weight: Vec<f64>,
}

impl Layer {
    /// A zeroed layer covering `rect`.
    pub fn new(rect: Rect) -> Self {
        Self {
            rect,
            sum: vec![[0.0; 3]; rect.area()],
            weight: vec![0.0; rect.area()],
        }
    }

    /// The pixels this layer covers.
    pub fn rect(&self) -> Rect {
        self.rect
    }

    fn index(&self, x: usize, y: usize) -> usize {
        assert!(
            self.rect.contains(x, y),
            "pixel ({x}, {y}) outside layer rect {:?}",
            self.rect
        );
        (y - self.rect.y0) * self.rect.width() + (x - self.rect.x0)
    }

    /// Adds `rgb` to the pixel's sum (in f64). Does not touch the weight.
    pub fn add(&mut self, x: usize, y: usize, rgb: [f32; 3]) {
        let i = self.index(x, y);
        let s = &mut self.sum[i];
        for c in 0..3 {
            s[c] += f64::from(rgb[c]);
        }
    }

    /// Adds an already-summed f64 value (a pixel's samples summed by the caller, in f64).
    pub fn add_f64(&mut self, x: usize, y: usize, rgb: [f64; 3]) {
        let i = self.index(x, y);
        let s = &mut self.sum[i];
        for c in 0..3 {
            s[c] += rgb[c];
        }
    }

    /// Adds `w` to the pixel's weight (sample count, or filter weight).
    pub fn add_weight(&mut self, x: usize, y: usize, w: f64) {
        let i = self.index(x, y);
        self.weight[i] += w;
    }

    /// The pixel's accumulated RGB sum.
    pub fn sum(&self, x: usize, y: usize) -> [f64; 3] {
        self.sum[self.index(x, y)]
    }

    /// The pixel's accumulated weight.
    pub fn weight(&self, x: usize, y: usize) -> f64 {
        self.weight[self.index(x, y)]
    }

    /// The normalised layer as an image of the layer's rectangle size. The division is done
    /// in f64; only the final per-pixel value is rounded to f32.
    pub fn resolve(&self, norm: Normalize) -> Image {
        let data = self
            .sum
            .iter()
            .zip(&self.weight)
            .map(|(s, &w)| {
                let d = match norm {
                    Normalize::Weight if w == 0.0 => return [0.0; 3],
                    Normalize::Weight => w,
                    Normalize::Constant(n) => n,
                };
                [(s[0] / d) as f32, (s[1] / d) as f32, (s[2] / d) as f32]
            })
            .collect();
        Image {
            width: self.rect.width(),
            height: self.rect.height(),
            data,
        }
    }

    /// Adds `other`'s sums and weights into the overlapping pixels of `self`.
    fn accumulate(&mut self, other: &Layer) {
        let r = other.rect;
        for y in r.y0..r.y1 {
            let dst = self.index(r.x0, y);
            let src = other.index(r.x0, y);
            for k in 0..r.width() {
                let (d, s) = (&mut self.sum[dst + k], other.sum[src + k]);
                for c in 0..3 {
                    d[c] += s[c];
                }
                self.weight[dst + k] += other.weight[src + k];
            }
        }
    }
}

/// Named layers, kept in insertion order.
fn find<'a>(layers: &'a [(String, Layer)], name: &str) -> Option<&'a Layer> {
    layers.iter().find(|(n, _)| n == name).map(|(_, l)| l)
}

fn find_or_insert<'a>(
    layers: &'a mut Vec<(String, Layer)>,
    name: &str,
    rect: Rect,
) -> &'a mut Layer {
    let i = match layers.iter().position(|(n, _)| n == name) {
        Some(i) => i,
        None => {
            layers.push((name.to_owned(), Layer::new(rect)));
            layers.len() - 1
        }
    };
    &mut layers[i].1
}

/// The film: a `width x height` image made of named [`Layer`]s ("direct", "caustic", ...).
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: usize,
    height: usize,
    layers: Vec<(String, Layer)>,
}

impl Film {
    /// An empty film (no layers yet).
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            layers: Vec::new(),
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// The layer `name`, created zeroed (full film size) if missing.
    pub fn layer_mut(&mut self, name: &str) -> &mut Layer {
        find_or_insert(&mut self.layers, name, Rect::full(self.width, self.height))
    }

    /// The layer `name`, if it exists.
    pub fn layer(&self, name: &str) -> Option<&Layer> {
        find(&self.layers, name)
    }

    /// Layer names in insertion order.
    pub fn layer_names(&self) -> Vec<&str> {
        self.layers.iter().map(|(n, _)| n.as_str()).collect()
    }

    /// A private, zeroed accumulation buffer for `rect`, with one layer per film layer
    /// (same names, same order). A worker fills it without locking, then hands it to
    /// [`Film::merge_tile`].
    ///
    /// # Panics
    /// If `rect` is not inside the film.
    pub fn tile_buffer(&self, rect: Rect) -> TileBuffer {
        assert!(
            rect.inside(self.width, self.height),
            "tile {rect:?} outside {}x{} film",
            self.width,
            self.height
        );
        TileBuffer {
            rect,
            layers: self
                .layers
                .iter()
                .map(|(n, _)| (n.clone(), Layer::new(rect)))
                .collect(),
        }
    }

    /// Adds a tile's sums and weights into the film. Each pixel receives exactly one f64
    /// addition per merged tile covering it, so when the merged tiles partition the image
    /// (as [`tiles`] does) the film is bit-identical whatever order the tiles arrive in.
    /// Layers the film lacks are appended in the tile's order; create all layers on the
    /// film before calling [`Film::tile_buffer`] to keep `layer_names` order-independent too.
    ///
    /// # Panics
    /// If the tile is not inside the film.
    pub fn merge_tile(&mut self, tile: &TileBuffer) {
        assert!(
            tile.rect.inside(self.width, self.height),
            "tile {:?} outside {}x{} film",
            tile.rect,
            self.width,
            self.height
        );
        for (name, layer) in &tile.layers {
            self.layer_mut(name).accumulate(layer);
        }
    }
}

/// A worker's private f64 accumulation over one rectangle of the film. Same [`Layer`]
/// API, in image coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct TileBuffer {
    rect: Rect,
    layers: Vec<(String, Layer)>,
}

impl TileBuffer {
    /// The pixels this tile owns.
    pub fn rect(&self) -> Rect {
        self.rect
    }

    /// The tile's layer `name`, created zeroed if missing.
    pub fn layer_mut(&mut self, name: &str) -> &mut Layer {
        find_or_insert(&mut self.layers, name, self.rect)
    }

    /// The tile's layer `name`, if it exists.
    pub fn layer(&self, name: &str) -> Option<&Layer> {
        find(&self.layers, name)
    }
}
