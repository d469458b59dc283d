// The lightning glow's composite: the float sum of the splats (lightningGlowSplatFS)
// added once to the frame (RGB blended GL_ONE, GL_ONE: one rounding to the frame's
// colour), its alpha made 1 where any splat was drawn (GL_ONE, GL_ONE_MINUS_SRC_ALPHA).
//VTK::System::Dec
in vec2 texCoord;
uniform sampler2D glowSum;
//VTK::Output::Dec

void main()
{
  vec4 sum = texture(glowSum, texCoord);
  if (sum.a <= 0.0)
  {
    discard;
  }
  gl_FragData[0] = vec4(sum.rgb, min(sum.a, 1.0));
}
