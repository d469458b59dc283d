// Final composite (000 Eq. 4): I_v = sum_i Delta I_v(t_i) + I_back g_view(T), with
// the sum and the cloud part of g_view accumulated by the slices (rgb, a), the
// atmosphere part of g_view computed here, and I_back the colour already in the
// framebuffer (background or opaque geometry). Optionally exposure and sRGB
// encoding for display.
in vec2 texCoord;
uniform sampler2D accumulation;
uniform sampler2D sceneColor;
uniform sampler2D rayEnds; // (t_end, t_ground) per pixel, this frame
uniform float exposure;
uniform int encodeSrgb;

vec3 ToLinear(vec3 c)
{
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}
vec3 ToSrgb(vec3 c)
{
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  vec4 sum = texture(accumulation, texCoord);
  vec4 background = texture(sceneColor, texCoord);
  float tEnd = texture(rayEnds, texCoord).r;
  vec3 behind = sum.a * AtmosphereViewTransmittance(origin, direction, tEnd);
  vec3 result;
  if (encodeSrgb != 0)
  {
    result = ToSrgb(exposure * sum.rgb + behind * ToLinear(background.rgb));
  }
  else
  {
    result = exposure * sum.rgb + behind * background.rgb;
  }
  gl_FragData[0] = vec4(result, 1.0);
  gl_FragDepth = texture(sceneDepth, texCoord).r;
}
