// Billboard splatting, the view pass: the billboard texture gives the cumulative density
// C through the ball at this fragment (CloudSplats.h SplatColumnTexture), the attenuation
// ratio is a = exp(-kappa C), the ball's scattered light ballColor (1 - a) (the ball's
// single scattering with the sun's light at its centre: the integral of
// sigma exp(-tau to the exit) along the column). Blended (GL_ONE, GL_ONE_MINUS_SRC_ALPHA):
// the framebuffer is multiplied by a and the colour added (002 §3.3).
//VTK::System::Dec
in vec2 corner;
in float kappa;
in vec3 ballColor;
uniform sampler2D billboard;
//VTK::Output::Dec

void main()
{
  if (dot(corner, corner) >= 1.0)
  {
    discard;
  }
  float column = texture(billboard, corner * 0.5 + 0.5).r;
  float opacity = 1.0 - exp(-kappa * column);
  gl_FragData[0] = vec4(ballColor * opacity, opacity);
}
