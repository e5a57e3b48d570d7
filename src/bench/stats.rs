//! Small statistics for the bench: medians of repeated timings, image error
//! metrics, the Pareto front of (run time, error) points, observed orders.

/// Median of `xs` (mean of the middle two for an even count); NaN if empty.
pub fn median(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// For each point (time, error), whether no other point is at least as good
/// in both and strictly better in one (lower time, lower error).
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    points
        .iter()
        .map(|&(t, e)| {
            !points
                .iter()
                .any(|&(t2, e2)| t2 <= t && e2 <= e && (t2 < t || e2 < e))
        })
        .collect()
}

/// Observed order of convergence between steps h and h/2 with errors
/// `e_coarse` and `e_fine`: log2(e_coarse / e_fine). NaN when undefined.
pub fn observed_order(e_coarse: f64, e_fine: f64) -> f64 {
    if e_coarse > 0.0 && e_fine > 0.0 {
        (e_coarse / e_fine).log2()
    } else {
        f64::NAN
    }
}

/// RGBA8 → RGB8 (drops alpha; headless frames are opaque).
pub fn rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Root-mean-square difference of two RGB8 images, on a 0..1 scale.
pub fn rmse(a_rgb: &[u8], b_rgb: &[u8]) -> f64 {
    assert_eq!(a_rgb.len(), b_rgb.len(), "images of different sizes");
    if a_rgb.is_empty() {
        return 0.0;
    }
    let sum: f64 = a_rgb
        .iter()
        .zip(b_rgb)
        .map(|(&a, &b)| {
            let d = (a as f64 - b as f64) / 255.0;
            d * d
        })
        .sum();
    (sum / a_rgb.len() as f64).sqrt()
}

/// Mean FLIP (nv-flip, default viewing conditions) of `test` against
/// `reference`, both RGB8 of `width`×`height`.
pub fn mean_flip(reference_rgb: &[u8], test_rgb: &[u8], width: u32, height: u32) -> f64 {
    let r = nv_flip::FlipImageRgb8::with_data(width, height, reference_rgb);
    let t = nv_flip::FlipImageRgb8::with_data(width, height, test_rgb);
    let map = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    nv_flip::FlipPool::from_image(&map).mean() as f64
}

/// Bilinear upscale (or downscale) of an RGBA8 image to `w`×`h`.
pub fn resize_rgba(rgba: &[u8], from_w: u32, from_h: u32, w: u32, h: u32) -> Vec<u8> {
    if (from_w, from_h) == (w, h) {
        return rgba.to_vec();
    }
    let img =
        image::RgbaImage::from_raw(from_w, from_h, rgba.to_vec()).expect("buffer matches its size");
    image::imageops::resize(&img, w, h, image::imageops::FilterType::Triangle).into_raw()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
    }

    #[test]
    fn pareto() {
        let pts = [(1.0, 0.5), (2.0, 0.2), (3.0, 0.3), (0.5, 0.9), (2.0, 0.2)];
        assert_eq!(pareto_front(&pts), vec![true, true, false, true, true]);
    }

    #[test]
    fn orders() {
        assert!((observed_order(0.4, 0.1) - 2.0).abs() < 1e-12);
        assert!(observed_order(0.0, 0.1).is_nan());
    }

    #[test]
    fn metrics_of_identical_and_different_images() {
        let a = vec![10u8; 3 * 16 * 16];
        let mut b = a.clone();
        assert_eq!(rmse(&a, &b), 0.0);
        assert!(mean_flip(&a, &b, 16, 16) < 1e-6);
        b.iter_mut().for_each(|x| *x = 250);
        assert!(rmse(&a, &b) > 0.9);
        assert!(mean_flip(&a, &b, 16, 16) > 0.3);
    }

    #[test]
    fn resize_keeps_a_flat_colour() {
        let img = vec![200u8; 4 * 8 * 6];
        let up = resize_rgba(&img, 8, 6, 16, 12);
        assert_eq!(up.len(), 4 * 16 * 12);
        assert!(up.iter().all(|&v| v == 200));
    }
}
