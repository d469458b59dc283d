// Shadow-surface update for slice i (000 Eq. 10): the shadow surface faces the sun;
// each texel adds the cloud optical depth of the slab along its sun ray,
// k_cl rho_cl(P_i) Delta s, by additive blending into a float target, so the
// product of Eq. 7 becomes a sum of optical depths (exact, and no underflow).
in vec2 texCoord;
uniform float sliceOffset;
uniform float sunStepMetres;
uniform float sliceSpacing; // Delta d (world)

void main()
{
  // Point of this texel's sun ray on the slice plane dot(x, n) = d_i.
  vec3 base = shadowOrigin + texCoord.x * shadowExtent.x * shadowU +
    texCoord.y * shadowExtent.y * shadowW;
  // This texel's plane of slice i (SliceJitter; a pattern other than the eye's).
  float planeOffset = sliceOffset + SliceJitterFraction(gl_FragCoord.yx) * sliceSpacing;
  float lambda = (planeOffset - dot(base, sliceNormal)) / dot(-sunDirection, sliceNormal);
  vec3 p = base - lambda * sunDirection;
  gl_FragData[0] = vec4(extinctionPerDensity * CloudDensity(p) * sunStepMetres, 0.0, 0.0, 0.0);
}
