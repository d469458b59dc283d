// The view lights' shafts drawn at a fraction of the pixels (cloudLightShaftsFS.glsl),
// brought to every pixel and added to the accumulation (additive blend): the four
// nearest texels, bilinear weights times how close each texel's ray end is to this
// pixel's (relative difference over 10 % weighs nothing), so a post's silhouette keeps
// the shafts of the rays that pass it off its own pixels; where no neighbour's end is
// close, the nearest in end distance.
in vec2 texCoord;
uniform sampler2D shafts;    // (radiance, ray end)
uniform sampler2D cloudSpan; // this pixel's ray end in w

void main()
{
  float tEnd = min(texture(cloudSpan, texCoord).w, 1e9);
  ivec2 size = textureSize(shafts, 0);
  vec2 p = texCoord * vec2(size) - 0.5;
  ivec2 base = ivec2(floor(p));
  vec2 f = p - floor(p);
  vec3 sum = vec3(0.0);
  float weights = 0.0;
  vec3 closest = vec3(0.0);
  float closestGap = kInfinity;
  for (int k = 0; k < 4; ++k)
  {
    ivec2 offset = ivec2(k & 1, k >> 1);
    vec4 texel = texelFetch(shafts, clamp(base + offset, ivec2(0), size - 1), 0);
    float gap = abs(min(texel.w, 1e9) - tEnd) / max(tEnd, 1e-6);
    float bilinear = (offset.x == 1 ? f.x : 1.0 - f.x) * (offset.y == 1 ? f.y : 1.0 - f.y);
    float w = bilinear * max(1.0 - gap / 0.1, 0.0);
    sum += w * texel.rgb;
    weights += w;
    if (gap < closestGap)
    {
      closestGap = gap;
      closest = texel.rgb;
    }
  }
  gl_FragData[0] = vec4(weights > 1e-3 ? sum / weights : closest, 0.0);
}
