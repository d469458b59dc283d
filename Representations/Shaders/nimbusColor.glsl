// The sRGB transfer functions (IEC 61966-2-1): the GLSL twins of
// Physics/SpectralColor.h (nimbus::SrgbEncode, nimbus::SrgbDecode), compared with
// them by the test TestShaderTwins. Inputs are clamped to [0, 1] (NaN: undefined in
// GLSL, 0 in C++).
float SrgbEncode(float linear)
{
  float c = clamp(linear, 0.0, 1.0);
  return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

float SrgbDecode(float encoded)
{
  float c = clamp(encoded, 0.0, 1.0);
  return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

vec3 SrgbEncode(vec3 linear)
{
  return vec3(SrgbEncode(linear.r), SrgbEncode(linear.g), SrgbEncode(linear.b));
}

vec3 SrgbDecode(vec3 encoded)
{
  return vec3(SrgbDecode(encoded.r), SrgbDecode(encoded.g), SrgbDecode(encoded.b));
}
