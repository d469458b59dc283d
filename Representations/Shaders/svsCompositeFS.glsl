// Final composite (000 Eq. 4): I_v = sum_i Delta I_v(t_i) + I_back g_view(T), with
// the sum and the cloud part of g_view accumulated by the slices (rgb, a), the
// atmosphere part of g_view computed here, and I_back the colour already in the
// framebuffer (background or opaque geometry). Display: displayScale per channel
// (Exposure, or a sky's exposure and white balance), optionally sRGB encoded.
//
// Over a Nimbus sky (skyBackground = 1) the framebuffer's background already is
// the sky L_sky of the sky-view table (all scattering orders, the whole ray), and
// the accumulation has a second target with the mapper's own radiance without
// the cloud, S_clear (unshadowed air and ground, same slices and steps). Where
// no opaque geometry was drawn:
//   I = S - T_cl S_clear + T_cl L_sky
// i.e. the sky, attenuated by the cloud's transmittance T_cl, plus what the
// cloud adds (its light, S - S_clear where T_cl = 1 inside the shafts' shadow:
// the missing sunlight, negative). Without a cloud on or shadowing the ray
// S = S_clear and T_cl = 1, so I = L_sky exactly: the sky is not changed where
// the cloud is not. The approximation: the air in front of a cloud keeps only
// its single scattering (the sky's multiple scattering is taken as hidden by
// the cloud in proportion 1 - T_cl along the whole ray).
in vec2 texCoord;
uniform sampler2D accumulation;
uniform sampler2D clearAccumulation; // S_clear (over a sky only)
uniform sampler2D sceneColor;
uniform vec3 displayScale;
uniform int encodeSrgb;
uniform int skyBackground;
// One piece of a distributed cloud (docs/parallel.md). premultipliedPiece:
// this piece's cloud alone, premultiplied (radiance, 1 - T_cl) over a transparent
// framebuffer, for IceT's "over" in visibility order. usePieceBackground: the rank
// that draws the air and the ground, last in that order, composites them over the
// view's background colour (as the framebuffer would hold it), which the parallel framebuffer
// does not hold, and is opaque.
uniform int premultipliedPiece;
// The view's lights drawn by virtual planes (cloudVirtualPlanesFS.glsl): their shafts'
// radiance toward the eye, added to the accumulation's.
uniform int lightsImageOn;
uniform sampler2D lightsImage;
// The lightning's delta-M view (svsSliceFS.glsl's third target): its light, attenuated
// by the reduced extinction, added to the accumulation's.
uniform int lightningImageOn;
uniform sampler2D lightningAccumulation;
uniform int usePieceBackground;
uniform vec3 pieceBackground;

void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  vec4 sum = texture(accumulation, texCoord);
  if (lightsImageOn != 0)
  {
    sum.rgb += texture(lightsImage, texCoord).rgb;
  }
  if (lightningImageOn != 0)
  {
    sum.rgb += texture(lightningAccumulation, texCoord).rgb;
  }
  vec4 background = texture(sceneColor, texCoord);
  float depth = texture(sceneDepth, texCoord).r;
  vec3 backgroundLinear = encodeSrgb != 0 ? SrgbDecode(background.rgb) : background.rgb;
  vec3 result;
  if (premultipliedPiece != 0)
  {
    // Opaque geometry drawn on this rank stays behind the cloud; elsewhere the
    // cloud's own opacity.
    vec3 color = displayScale * sum.rgb + (depth < 1.0 ? sum.a * backgroundLinear : vec3(0.0));
    float alpha = depth < 1.0 ? 1.0 : 1.0 - sum.a;
    if (encodeSrgb != 0)
    {
      // Encoded unpremultiplied, then premultiplied: exact where one piece covers a
      // pixel; where several do, "over" then blends encoded values (measured).
      color = alpha > 0.0 ? SrgbEncode(color / alpha) * alpha : vec3(0.0);
    }
    gl_FragData[0] = vec4(color, alpha);
    gl_FragDepth = depth;
    return;
  }
  if (usePieceBackground != 0 && depth >= 1.0)
  {
    backgroundLinear = encodeSrgb != 0 ? SrgbDecode(pieceBackground) : pieceBackground;
  }
  if (skyBackground != 0 && depth >= 1.0)
  {
    vec3 clearSum = texture(clearAccumulation, texCoord).rgb;
    vec3 sky = sum.a * backgroundLinear;                       // T_cl L_sky (display)
    vec3 deficit = displayScale * (sum.a * clearSum - sum.rgb); // > 0: light the cloud removes
    // The mapper's RGB single scattering and the spectral sky differ by a few
    // per cent (up to +7 % in red on sunlit ground with the sun 4 deg high,
    // measured): a deep shadow's deficit may then exceed the sky in one channel.
    // Scale it down as a whole there, so the shadow keeps its hue instead of
    // clipping that channel to zero.
    float fit = 1.0;
    for (int c = 0; c < 3; ++c)
    {
      if (deficit[c] > sky[c])
      {
        fit = min(fit, sky[c] / deficit[c]);
      }
    }
    result = max(sky - max(fit, 0.0) * deficit, 0.0);
  }
  else
  {
    // Where the view ray ends, at this pixel's own position when the passes drew a
    // smaller image.
    float tGround;
    float tEnd = RayEnd(texCoord, origin, direction, tGround);
    vec3 behind = sum.a * AtmosphereViewTransmittance(origin, direction, tEnd);
    result = displayScale * sum.rgb + behind * backgroundLinear;
  }
  gl_FragData[0] = vec4(encodeSrgb != 0 ? SrgbEncode(result) : result, 1.0);
  gl_FragDepth = depth;
}
