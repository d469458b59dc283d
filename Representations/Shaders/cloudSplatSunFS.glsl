// Billboard splatting, the sun's pass: each fragment of a sun-facing square adds the
// optical depth kappa P(u, h) of the part of its ball's column in front of the layer's
// plane (P: CloudSplats.h SplatPartialColumnTable, u the distance from the centre and h
// the plane's offset, both in units of R), summed additively (GL_ONE, GL_ONE) into the
// layer of the sun's accumulation texture. With `multiply` (the read-back variant) it
// writes the whole column's attenuation ratio exp(-kappa C(u)) instead, which the
// framebuffer multiplies in (GL_ZERO, GL_SRC_COLOR).
//VTK::System::Dec
in vec2 corner;
in float kappa;
in float planeOffset;
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
  float h = multiply != 0 ? 1.0 : clamp(planeOffset, -1.0, 1.0);
  vec2 uv = (vec2(u, h * 0.5 + 0.5) * (size - 1.0) + 0.5) / size;
  float tau = kappa * texture(partialColumn, uv).r;
  gl_FragData[0] = vec4(multiply != 0 ? exp(-tau) : tau, 0.0, 0.0, 1.0);
}
