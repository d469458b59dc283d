// The view lights' shafts in the air (LightsInAir, nimbusLights.glsl) drawn at a
// fraction of the view's pixels (LightShaftDownsampling): each texel's ray through its
// centre, ending where the march's span target says (the full-size pixel under it:
// the cloud's first and last occupied distance, its transmittance, the ray's end).
// Output: (radiance of the shafts, the ray's end), for cloudLightShaftsUpsampleFS.glsl.
in vec2 texCoord;
uniform sampler2D cloudSpan;  // (first, last, cloud transmittance, ray end) per full pixel
uniform int lightSamples;
uniform float lightsMieG;

vec3 LightsViewTransmittance(vec3 origin, vec3 direction, float t)
{
  return AtmosphereViewTransmittance(origin, direction, t);
}

void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  vec4 span = texture(cloudSpan, texCoord);
  vec3 shafts = LightsInAir(origin, direction, 0.0, span.w, lightSamples,
    SliceJitterFraction(gl_FragCoord.xy) + 0.5, lightsMieG, span.x, span.y, span.z);
  gl_FragData[0] = vec4(shafts, span.w);
}
