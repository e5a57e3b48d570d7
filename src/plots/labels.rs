//! Text labels drawn into a rendered frame after readback (the cloud-types
//! scene names each of its clouds): plotters' bitmap backend over the RGB
//! channels, the embedded font of [`super::register_fonts`], light text on
//! a dark one-pixel shadow so it reads over sky and cloud alike.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::error::{Error, Result};

/// A label: text centred on pixel column x, its bottom edge at row y.
#[derive(Debug, Clone, PartialEq)]
pub struct Label {
    pub x: f32,
    pub y: f32,
    pub text: String,
}

/// Draws `labels` into tightly packed RGBA8 rows of `width` × `height`
/// (alpha untouched); labels outside the frame are clipped.
pub fn draw_labels(rgba: &mut [u8], width: u32, height: u32, labels: &[Label]) -> Result<()> {
    if labels.is_empty() {
        return Ok(());
    }
    super::register_fonts();
    let mut rgb: Vec<u8> = rgba
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let size = (height as f64 / 36.0).clamp(11.0, 28.0);
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        let pos = Pos::new(HPos::Center, VPos::Bottom);
        for l in labels {
            let (x, y) = (l.x.round() as i32, l.y.round() as i32);
            for (dx, dy, color) in [(1, 1, BLACK), (0, 0, WHITE)] {
                let style = ("sans-serif", size).into_font().color(&color).pos(pos);
                root.draw(&Text::new(l.text.clone(), (x + dx, y + dy), style))
                    .map_err(|e| Error::invalid("label", &l.text, e.to_string()))?;
            }
        }
        root.present()
            .map_err(|e| Error::invalid("labels", labels.len(), e.to_string()))?;
    }
    for (p, c) in rgba.chunks_exact_mut(4).zip(rgb.chunks_exact(3)) {
        p[..3].copy_from_slice(c);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_label_changes_pixels_where_it_is_and_nowhere_far() {
        let (w, h) = (200u32, 100u32);
        let mut img = vec![100u8; (w * h * 4) as usize];
        let label = Label {
            x: 100.0,
            y: 40.0,
            text: "cirrus".into(),
        };
        draw_labels(&mut img, w, h, &[label]).unwrap();
        let px = |x: u32, y: u32| &img[((y * w + x) * 4) as usize..][..4];
        let changed = (30..70)
            .flat_map(|y| (60..140).map(move |x| (x, y)))
            .filter(|&(x, y)| px(x, y)[..3] != [100, 100, 100])
            .count();
        assert!(changed > 20, "{changed} pixels of text");
        assert_eq!(px(5, 5), &[100, 100, 100, 100]);
        assert_eq!(px(195, 95), &[100, 100, 100, 100]);
    }
}
