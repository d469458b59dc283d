// Billboard splatting, the sun's pass: each fragment of a sun-facing square adds the
// optical depth kappa (P(u, h_k) - P(u, h_{k-1})) of the part of its ball's column in the
// slab between the previous layer's plane and this one (P: CloudSplats.h
// SplatPartialColumnTable, u the distance from the centre and h the planes' offsets, in
// units of R), summed additively (GL_ONE, GL_ONE) into the running sum that becomes the
// layer of the sun's accumulation texture. With `multiply` (the read-back variant) it
// writes the whole column's attenuation ratio exp(-kappa C(u)) instead, which the
// framebuffer multiplies in (GL_ZERO, GL_SRC_COLOR).
//VTK::System::Dec
in vec2 corner;
in float kappa;
in vec2 planeOffsets;
uniform sampler2D partialColumn; // P(u, h): u across, h in [-1, 1] up
uniform int multiply;
//VTK::Output::Dec

void main()
{
  float u = length(corner);
  if (u >= 1.0)
  {
    discard;
  }
  vec2 size = vec2(textureSize(partialColumn, 0));
  vec2 h = multiply != 0 ? vec2(1.0, -1.0) : clamp(planeOffsets, -1.0, 1.0);
  float x = (u * (size.x - 1.0) + 0.5) / size.x;
  vec2 y = ((h * 0.5 + 0.5) * (size.y - 1.0) + 0.5) / size.y;
  float tau = kappa *
    (texture(partialColumn, vec2(x, y.x)).r - texture(partialColumn, vec2(x, y.y)).r);
  gl_FragData[0] = vec4(multiply != 0 ? exp(-tau) : tau, 0.0, 0.0, 1.0);
}
