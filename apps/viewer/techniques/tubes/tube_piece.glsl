// One quadratic Bézier piece of a tube and the oriented box around it
// (written by tube_pieces.comp.glsl, read by the box proxies and the ray
// caster). c0..c2: control points (xyz, world mm) with the radius at each in
// w (negative: an empty piece). center.xyz: the box centre, center.w the
// fiber index (uint bits). axis*: unit box axes (x along the chord, y the
// control polygon's bend made perpendicular, z = x × y), w the half extent.
// values: the per-point values (point_values.glsl) at t = 0, 0.5 and 1.
struct TubePiece {
    vec4 c0, c1, c2;
    vec4 center;
    vec4 axisX, axisY, axisZ;
    vec4 values;
};
