#version 450
// The proxy of each tube piece: its oriented box as 12 triangles (36
// vertices per piece, outward counter-clockwise; the back faces are culled).
// Empty pieces are sent outside the clip volume.
#include "tube_piece.glsl"

layout(std430, binding = BINDING_TUBE_PIECES) readonly buffer Pieces { TubePiece pieces[]; };

uniform mat4 uViewProjection;

layout(location = 0) flat out uint vPiece;
layout(location = 1) out vec3 vWorld;

// Corners: bit 0 x, bit 1 y, bit 2 z (0: -half, 1: +half).
const uint kCorners[36] = uint[36](4u, 6u, 2u, 4u, 2u, 0u, 1u, 3u, 7u, 1u, 7u, 5u, 0u, 1u, 5u, 0u, 5u, 4u,
                                   6u, 7u, 3u, 6u, 3u, 2u, 2u, 3u, 1u, 2u, 1u, 0u, 4u, 5u, 7u, 4u, 7u, 6u);

void main() {
    uint v = uint(gl_VertexID);
    uint piece = v / 36u;
    TubePiece q = pieces[piece];
    vPiece = piece;
    if (q.c0.w < 0.0) {
        vWorld = vec3(0.0);
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    uint c = kCorners[v % 36u];
    vec3 s = vec3(float(c & 1u), float((c >> 1) & 1u), float((c >> 2) & 1u)) * 2.0 - 1.0;
    vWorld = q.center.xyz + s.x * q.axisX.w * q.axisX.xyz + s.y * q.axisY.w * q.axisY.xyz + s.z * q.axisZ.w * q.axisZ.xyz;
    gl_Position = uViewProjection * vec4(vWorld, 1.0);
}
