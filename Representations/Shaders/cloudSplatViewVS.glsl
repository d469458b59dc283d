// Billboard splatting of metaball clouds (002 §3.3), the view pass
// (vtkNimbusCloudSplatMapper): one square per metaball facing the viewer, back to front,
// drawn instanced (four corners per instance, from gl_VertexID). The ball's colour is its
// single scattering: albedo x phase x the sun's colour x the sun's transmittance at the
// centre, from the sun pass (the accumulation texture, or the value read back per ball).
// With SUN_SAMPLES (the accumulation texture and SunLightSamples > 0) the fragment shader
// integrates the light along its own column instead (cloudSplatViewFS.glsl); this shader
// then hands it the billboard's point and the ball.
// With MULTIPLE_SCATTERING (MultipleScattering on, the light at the centre) the ball's
// colour adds the sun's light scattered more than once, read at its centre: the solver's
// in-scattered radiance J(centre, toward the eye) and the delta-M forward peak's part
// (J holds the sky's light too over a sky with SkyLight, and only that without
// MultipleScattering: then the forward peak's part is 0).
// Over a sky (vtkNimbusCloudSplatMapper::SetSky) the ball brings the air's tint of the
// sun at its centre (E_sun(z) / E_sun above the air) and the air between the eye and it
// (transmittance, in-scattered radiance x display scale), handed to the fragment shader.
//VTK::System::Dec
//NIMBUS::Library
in vec4 ball;       // xyz: the centre (world), w: the radius R (world units)
in vec2 ballOptics; // x: kappa = k d R, y: the sun's transmittance read back (read-back variant)
in vec3 ballTint;             // the sun's tint by the air at the centre (1 without air)
in vec3 ballAirTransmittance; // the air's, eye to centre (1 without air)
in vec3 ballAirRadiance;      // the air's in-scattered radiance x display scale (0 without)
uniform mat4 MCVCMatrix;
uniform mat4 VCDCMatrix;
uniform vec3 eyeWorld;
uniform vec3 toSun;
uniform vec3 sunAxisX;
uniform vec3 sunAxisY;
uniform vec4 sunRect;        // the sun texture's window (as cloudSplatSunVS)
uniform vec2 sunDepthRange;  // (depth of layer 0, 1 / (depth of the last layer - that))
// (the mapper defines SUN_TEXTURE on the next line for the accumulation texture)
//SPLAT::SunTexture
#ifdef SUN_TEXTURE
uniform sampler3D sunDepth;  // the accumulated optical depth toward the sun, per layer
#endif
uniform vec3 sunColor;       // the sun's irradiance (linear sRGB) x exposure
uniform float albedo;
uniform float cloudG;
// (the mapper defines MULTIPLE_SCATTERING on the next line)
//SPLAT::MultipleScattering
#ifdef MULTIPLE_SCATTERING
uniform sampler3D scatteringRed; // J's SH c_00, c_1-1, c_10, c_11 per colour
uniform sampler3D scatteringGreen;
uniform sampler3D scatteringBlue;
uniform vec3 scatteringScale; // texture coordinate = x scatteringScale + scatteringOffset
uniform vec3 scatteringOffset;
uniform vec3 lightScale; // the display scale (exposure, or the sky's exposure x white balance)
uniform float forwardPeakFraction; // f, the delta-M forward fraction of the solve

// J(x, w): the radiance the cloud's particles scatter toward w (direction of travel) per
// unit scattering coefficient, orders >= 2 of the sun (Physics/MultipleScattering.h).
vec3 SplatInScattering(vec3 x, vec3 w)
{
  vec3 tc = x * scatteringScale + scatteringOffset;
  vec4 y = vec4(0.2820948, 0.4886025 * w.y, 0.4886025 * w.z, 0.4886025 * w.x);
  return max(vec3(dot(texture(scatteringRed, tc), y), dot(texture(scatteringGreen, tc), y),
               dot(texture(scatteringBlue, tc), y)), vec3(0.0));
}
#endif
uniform vec3 viewRight; // the camera's axes in world coordinates (the billboard's plane)
uniform vec3 viewUp;
out vec2 corner;
out float kappa;
out vec3 ballColor;
out vec3 billboardPoint; // world
flat out vec4 ballWorld;
flat out vec3 sunTint;
flat out vec3 airTransmittance;
flat out vec3 airRadiance;

void main()
{
  corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
  vec4 centre = MCVCMatrix * vec4(ball.xyz, 1.0);
  centre.xy += corner * ball.w * centre.w;
  gl_Position = VCDCMatrix * centre;
  kappa = ballOptics.x;
  billboardPoint = ball.xyz + (viewRight * corner.x + viewUp * corner.y) * ball.w;
  ballWorld = ball;
  sunTint = ballTint;
  airTransmittance = ballAirTransmittance;
  airRadiance = ballAirRadiance;

  float sunTransmittance = ballOptics.y;
#ifdef SUN_TEXTURE
  {
    vec3 size = vec3(textureSize(sunDepth, 0));
    vec3 s = vec3((vec2(dot(ball.xyz, sunAxisX), dot(ball.xyz, sunAxisY)) - sunRect.xy) *
        sunRect.zw,
      (-dot(ball.xyz, toSun) - sunDepthRange.x) * sunDepthRange.y);
    s.z = (s.z * (size.z - 1.0) + 0.5) / size.z; // layers at texel centres
    sunTransmittance = exp(-texture(sunDepth, s).r);
  }
#endif
  // The scattering angle: the sunlight's direction (-toSun) against the way to the eye.
  float mu = dot(-toSun, normalize(eyeWorld - ball.xyz));
  ballColor = albedo * CornetteShanks(mu, cloudG) * sunColor * ballTint * sunTransmittance;
#ifdef MULTIPLE_SCATTERING
  {
    // The forward peak the delta-M solve left on the sun's direction (as the cloud
    // mapper's SunMultipleScattering) and J toward the eye.
    float tau = -log(max(sunTransmittance, 1e-30));
    float peak = (1.0 - forwardPeakFraction) *
      (exp(-(1.0 - forwardPeakFraction * albedo) * tau) - sunTransmittance);
    ballColor += albedo * (CornetteShanks(mu, cloudG) * sunColor * ballTint * peak +
                   lightScale * SplatInScattering(ball.xyz, normalize(eyeWorld - ball.xyz)));
  }
#endif
}
