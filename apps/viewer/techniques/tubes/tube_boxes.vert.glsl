#version 450
// The proxy of each tube piece: its oriented box (box_proxy.glsl). Empty
// pieces are sent outside the clip volume.
#include "tube_piece.glsl"
#include "box_proxy.glsl"

layout(std430, binding = BINDING_TUBE_PIECES) readonly buffer Pieces { TubePiece pieces[]; };

uniform mat4 uViewProjection;

layout(location = 0) flat out uint vPiece;
layout(location = 1) out vec3 vWorld;

void main() {
    uint v = uint(gl_VertexID);
    uint piece = v / kBoxVertices;
    TubePiece q = pieces[piece];
    vPiece = piece;
    if (q.c0.w < 0.0) {
        vWorld = vec3(0.0);
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    vWorld = boxCorner(v, q.center.xyz, q.axisX.xyz, q.axisY.xyz, q.axisZ.xyz, vec3(q.axisX.w, q.axisY.w, q.axisZ.w));
    gl_Position = uViewProjection * vec4(vWorld, 1.0);
}
