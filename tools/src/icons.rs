//! The FMI 3.0 FMUs' icons (`terminalsAndIcons/icon.{svg,png}`, FMI 3.0 section 2.4.9.1) and
//! their flanges' icons (`translational_flange` and `rotational_flange`), drawn from one list of
//! shapes per picture: written as SVG text and rendered to PNG (tiny-skia), so both files show the
//! same picture. Coordinates are the icon's own (FMI 3.0's default coordinate system,
//! `-100..100` on both axes, y up); there is no text, so nothing depends on fonts.

use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};

/// Side of the FMU icon's PNG, px (20 mm at FMI 3.0's default scale: about 325 dpi).
pub const ICON_PX: u32 = 256;
/// Side of a flange icon's PNG, px.
pub const FLANGE_PX: u32 = 64;

type Rgb = (u8, u8, u8);

const FRAME: Rgb = (0, 0, 127);
const RUBBER: Rgb = (240, 180, 110);
const BRAID: Rgb = (90, 60, 30);
const STEEL: Rgb = (150, 150, 150);
const DARK: Rgb = (40, 40, 40);
const WHITE: Rgb = (255, 255, 255);
const GREEN: Rgb = (0, 127, 0);
const BLUE: Rgb = (70, 110, 200);

/// One filled and/or stroked outline.
struct Shape {
    points: Vec<(f32, f32)>,
    closed: bool,
    fill: Option<Rgb>,
    stroke: Option<(Rgb, f32)>,
}

fn polygon(points: Vec<(f32, f32)>, fill: Rgb, stroke: Option<(Rgb, f32)>) -> Shape {
    Shape {
        points,
        closed: true,
        fill: Some(fill),
        stroke,
    }
}

fn line(points: Vec<(f32, f32)>, color: Rgb, width: f32) -> Shape {
    Shape {
        points,
        closed: false,
        fill: None,
        stroke: Some((color, width)),
    }
}

fn rect(x1: f32, y1: f32, x2: f32, y2: f32, fill: Rgb, stroke: Option<(Rgb, f32)>) -> Shape {
    polygon(vec![(x1, y1), (x2, y1), (x2, y2), (x1, y2)], fill, stroke)
}

fn circle(cx: f32, cy: f32, r: f32, fill: Option<Rgb>, stroke: Option<(Rgb, f32)>) -> Shape {
    Shape {
        points: arc(cx, cy, r, 0.0, 360.0, 72),
        closed: true,
        fill,
        stroke,
    }
}

/// Points on a circular arc from `from` to `to` degrees.
fn arc(cx: f32, cy: f32, r: f32, from: f32, to: f32, steps: usize) -> Vec<(f32, f32)> {
    (0..=steps)
        .map(|i| {
            let a = (from + (to - from) * i as f32 / steps as f32).to_radians();
            (cx + r * a.cos(), cy + r * a.sin())
        })
        .collect()
}

/// A McKibben spindle between `x0` and `x1` around height `y`, `h` its largest half-height: its
/// rubber, end fittings and, with `braid`, the two helices of strands crossing over it.
fn spindle(x0: f32, x1: f32, y: f32, h: f32, braid: bool) -> Vec<Shape> {
    let n = 40;
    let half = |x: f32| {
        let t = (2.0 * (x - x0) / (x1 - x0) - 1.0).clamp(-1.0, 1.0);
        h * (1.0 - t * t).sqrt().max(0.25)
    };
    let xs: Vec<f32> = (0..=n)
        .map(|i| x0 + (x1 - x0) * i as f32 / n as f32)
        .collect();
    let mut outline: Vec<(f32, f32)> = xs.iter().map(|&x| (x, y + half(x))).collect();
    outline.extend(xs.iter().rev().map(|&x| (x, y - half(x))));
    let mut shapes = vec![polygon(outline, RUBBER, Some((BRAID, 2.0)))];
    if braid {
        // Strands: chords from the top to the bottom outline, leaning both ways.
        let pitch = (x1 - x0) / 8.0;
        for k in 0..8 {
            let a = x0 + pitch * (k as f32 + 0.5);
            let b = a + pitch;
            if b <= x1 {
                shapes.push(line(vec![(a, y + half(a)), (b, y - half(b))], BRAID, 1.5));
                shapes.push(line(vec![(a, y - half(a)), (b, y + half(b))], BRAID, 1.5));
            }
        }
    }
    let cap = 0.3 * h;
    shapes.push(rect(
        x0 - 8.0,
        y - cap,
        x0 + 2.0,
        y + cap,
        STEEL,
        Some((DARK, 1.5)),
    ));
    shapes.push(rect(
        x1 - 2.0,
        y - cap,
        x1 + 8.0,
        y + cap,
        STEEL,
        Some((DARK, 1.5)),
    ));
    shapes
}

/// The picture of the FMU `model` (a plain frame for a model without its own).
fn fmu_shapes(model: &str) -> Vec<Shape> {
    let mut s = vec![rect(
        -100.0,
        -100.0,
        100.0,
        100.0,
        WHITE,
        Some((FRAME, 4.0)),
    )];
    match model {
        "McKibbenMuscle" => s.extend(spindle(-78.0, 78.0, 0.0, 40.0, true)),
        "KnittedMuscle" => {
            s.extend(spindle(-78.0, 78.0, 0.0, 40.0, false));
            // Knit loops: rows of small rings over the rubber.
            for row in [-18.0, 0.0, 18.0] {
                for k in 0..7 {
                    let x = -54.0 + 18.0 * k as f32;
                    s.push(circle(x, row, 6.0, None, Some((BRAID, 1.5))));
                }
            }
        }
        "FreeBladder" => {
            s.extend(spindle(-78.0, 78.0, 0.0, 30.0, false));
            // Its clamps, no sleeve.
            s.push(rect(-92.0, -20.0, -80.0, 20.0, DARK, None));
            s.push(rect(80.0, -20.0, 92.0, 20.0, DARK, None));
        }
        "McKibbenJoint" => {
            s.push(circle(45.0, 0.0, 32.0, Some(STEEL), Some((DARK, 2.0))));
            s.extend(spindle(-85.0, 45.0, 32.0, 14.0, true));
            s.extend(spindle(-85.0, 45.0, -32.0, 14.0, true));
            s.push(line(vec![(45.0, 0.0), (88.0, 50.0)], DARK, 6.0));
            s.push(circle(45.0, 0.0, 5.0, Some(DARK), None));
        }
        "PulleyJoint" => {
            s.push(circle(0.0, 25.0, 45.0, Some(STEEL), Some((DARK, 2.0))));
            let mut cable = vec![(-45.0, -85.0)];
            cable.extend(arc(0.0, 25.0, 45.0, 180.0, 0.0, 36));
            cable.push((45.0, -85.0));
            s.push(line(cable, BLUE, 4.0));
            s.push(line(vec![(0.0, 25.0), (60.0, 85.0)], DARK, 6.0));
            s.push(circle(0.0, 25.0, 6.0, Some(DARK), None));
        }
        "MultiferroicMotor" => {
            s.push(circle(0.0, 0.0, 75.0, None, Some((DARK, 4.0))));
            // The strain direction's 60-degree steps.
            for k in 0..6 {
                let a = (60.0 * k as f32).to_radians();
                let (c, si) = (a.cos(), a.sin());
                s.push(line(
                    vec![(62.0 * c, 62.0 * si), (88.0 * c, 88.0 * si)],
                    BLUE,
                    5.0,
                ));
            }
            s.push(circle(0.0, 0.0, 45.0, Some(STEEL), Some((DARK, 2.0))));
            // The rotor's magnetization: an arrow along 60 degrees.
            let (c, si) = (60f32.to_radians().cos(), 60f32.to_radians().sin());
            s.push(line(
                vec![(-38.0 * c, -38.0 * si), (30.0 * c, 30.0 * si)],
                DARK,
                6.0,
            ));
            let (tip, back) = ((42.0 * c, 42.0 * si), (24.0, 12.0));
            let (nx, ny) = (-si, c);
            s.push(polygon(
                vec![
                    tip,
                    (
                        tip.0 - back.0 * c + back.1 * nx,
                        tip.1 - back.0 * si + back.1 * ny,
                    ),
                    (
                        tip.0 - back.0 * c - back.1 * nx,
                        tip.1 - back.0 * si - back.1 * ny,
                    ),
                ],
                DARK,
                None,
            ));
        }
        "PassThrough" => {
            s.push(line(vec![(-75.0, 0.0), (40.0, 0.0)], BLUE, 8.0));
            s.push(polygon(
                vec![(75.0, 0.0), (35.0, 25.0), (35.0, -25.0)],
                BLUE,
                None,
            ));
        }
        _ => {}
    }
    s
}

/// The flange icon of a terminal kind: Modelica's translational flange (a green square) or
/// rotational flange (a grey disc).
fn flange_shapes(rotational: bool) -> Vec<Shape> {
    if rotational {
        vec![circle(0.0, 0.0, 96.0, Some(STEEL), Some((DARK, 8.0)))]
    } else {
        vec![rect(-96.0, -96.0, 96.0, 96.0, GREEN, Some((DARK, 8.0)))]
    }
}

fn svg(shapes: &[Shape]) -> String {
    let color = |(r, g, b): Rgb| format!("rgb({r},{g},{b})");
    let mut out = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- Generated by package_fmi3 (tools/src/icons.rs). -->\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"200\" viewBox=\"-100 -100 200 200\">\n<g transform=\"scale(1,-1)\" stroke-linejoin=\"round\" stroke-linecap=\"round\">\n",
    );
    for s in shapes {
        let points: Vec<String> = s
            .points
            .iter()
            .map(|(x, y)| format!("{x:.2},{y:.2}"))
            .collect();
        let element = if s.closed { "polygon" } else { "polyline" };
        let fill = s.fill.map_or("none".to_string(), color);
        let stroke = s.stroke.map_or(String::from("stroke=\"none\""), |(c, w)| {
            format!("stroke=\"{}\" stroke-width=\"{w}\"", color(c))
        });
        out.push_str(&format!(
            "  <{element} points=\"{}\" fill=\"{fill}\" {stroke}/>\n",
            points.join(" ")
        ));
    }
    out.push_str("</g>\n</svg>\n");
    out
}

fn png(shapes: &[Shape], px: u32) -> Result<Vec<u8>, String> {
    let mut pixmap = Pixmap::new(px, px).ok_or("icon size is zero")?;
    let scale = px as f32 / 200.0;
    // Icon coordinates (y up, -100..100) to pixels (y down).
    let transform = Transform::from_row(scale, 0.0, 0.0, -scale, 100.0 * scale, 100.0 * scale);
    for s in shapes {
        let mut pb = PathBuilder::new();
        let Some((&(x, y), rest)) = s.points.split_first() else {
            continue;
        };
        pb.move_to(x, y);
        for &(x, y) in rest {
            pb.line_to(x, y);
        }
        if s.closed {
            pb.close();
        }
        let path = pb
            .finish()
            .ok_or("an icon shape has no area and no length")?;
        let mut paint = Paint {
            anti_alias: true,
            ..Paint::default()
        };
        if let Some((r, g, b)) = s.fill {
            paint.set_color_rgba8(r, g, b, 255);
            pixmap.fill_path(&path, &paint, FillRule::Winding, transform, None);
        }
        if let Some(((r, g, b), width)) = s.stroke {
            paint.set_color_rgba8(r, g, b, 255);
            let stroke = Stroke {
                width,
                line_join: tiny_skia::LineJoin::Round,
                line_cap: tiny_skia::LineCap::Round,
                ..Stroke::default()
            };
            pixmap.stroke_path(&path, &paint, &stroke, transform, None);
        }
    }
    pixmap.encode_png().map_err(|e| e.to_string())
}

/// The icon of the FMU `model`: (SVG text, PNG bytes).
pub fn fmu_icon(model: &str) -> Result<(String, Vec<u8>), String> {
    let shapes = fmu_shapes(model);
    Ok((svg(&shapes), png(&shapes, ICON_PX)?))
}

/// The icon of a flange terminal (`iconBaseName` `translational_flange` or `rotational_flange`):
/// (SVG text, PNG bytes).
pub fn flange_icon(icon_base_name: &str) -> Result<(String, Vec<u8>), String> {
    let shapes = match icon_base_name {
        "translational_flange" => flange_shapes(false),
        "rotational_flange" => flange_shapes(true),
        other => return Err(format!("no icon named {other}")),
    };
    Ok((svg(&shapes), png(&shapes, FLANGE_PX)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_picture_renders_in_both_formats() {
        for model in [
            "McKibbenMuscle",
            "KnittedMuscle",
            "FreeBladder",
            "McKibbenJoint",
            "PulleyJoint",
            "MultiferroicMotor",
            "PassThrough",
            "AnyOther",
        ] {
            let (svg, png) = fmu_icon(model).unwrap();
            assert!(svg.contains("viewBox=\"-100 -100 200 200\""));
            assert_eq!(&png[1..4], b"PNG");
        }
        for name in ["translational_flange", "rotational_flange"] {
            assert!(flange_icon(name).is_ok());
        }
        assert!(flange_icon("x").is_err());
    }
}
