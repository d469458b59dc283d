// The lightning glow's splats: the single-scattering radiance of a point source in air
// seen at impact parameter b, L(b) = sigma_s I / (4 b) (Physics/Lightning.h,
// LightningGlowRadiance), x exposure x colour, held at its value at the channel's
// radius near the centre and cut off smoothly at the glow radius R: x (1 - (b/R)^2)^2.
// Summed additively (GL_ONE, GL_ONE) in a float target; alpha counts the splats.
//VTK::System::Dec
in vec2 offset;
in float intensity;
uniform float gain;       // sigma_s / (4 R) x exposure: L at b = R for I = 1
uniform float innerLimit; // the channel's radius / R (at most 1)
uniform vec3 glowColor;
//VTK::Output::Dec

void main()
{
  float b = length(offset);
  if (b > 1.0)
  {
    discard;
  }
  float fade = (1.0 - b * b) * (1.0 - b * b);
  float glow = gain * intensity / max(b, innerLimit) * fade;
  gl_FragData[0] = vec4(glow * glowColor, 1.0);
}
