// The sky-view table lookup shared by the sky pass and the sky background
// (vtkNimbusSkyPass, vtkNimbusSkyBackground): the GPU twin of
// nimbus::SkyViewLut::Radiance (Physics/Sky.cxx): SkyViewRow and SkyViewTexel are
// the twins of nimbus::SkyViewMapping::Row and ::Texel (compared by TestShaderTwins),
// the phase functions are nimbusPhase.glsl's. Plus the limb-darkened sun disc.
// Needs nimbusPhase.glsl (//NIMBUS::Library). Uniforms are set by
// nimbus::SkyViewTextures (Sky/SkyViewTextures.cxx).
//
// L = p_R(nu) A_R + p_M(nu) A_M + A_I  (Sky.h), nu = dot(view, sun).
uniform sampler2D skyRayleigh;
uniform sampler2D skyMie;
uniform sampler2D skyIsotropic;
uniform vec3 sunDirection;     // unit, toward the sun, scene frame (z up)
uniform float sunAzimuthRadians; // from +y toward +x
uniform float mieG;
uniform vec3 displayScale;     // exposure / sun colour, per channel
uniform vec4 skyTable;         // horizon zenith (rad), width, rows above, rows below
uniform int sunDisc;
uniform vec3 sunDiscRadiance;
uniform float sunAngularRadius; // rad

// SkyViewMapping::Row: rows [0, above-1] from the horizon up (zenith th (1 - s^3)),
// rows [above, above+below-1] from the horizon down (th + s^3 (pi - th)).
float SkyViewRow(float zenith, vec4 table)
{
  float th = table.x;
  if (zenith <= th)
  {
    float a = clamp((th - zenith) / th, 0.0, 1.0);
    return pow(a, 1.0 / 3.0) * (table.z - 1.0);
  }
  float b = clamp((zenith - th) / (kPi - th), 0.0, 1.0);
  return table.z + pow(b, 1.0 / 3.0) * (table.w - 1.0);
}

// SkyViewMapping::Texel: (column, row) of unit direction w; the column is the
// azimuth from the sun in [0, pi].
vec2 SkyViewTexel(vec3 w, float sunAzimuth, vec4 table)
{
  // atan, not acos: GPUs' float acos is coarse (1e-4 rad measured on llvmpipe), and
  // near the horizon the cube-root rows magnify it to a sixth of a row.
  float zenith = atan(length(w.xy), w.z);
  float row = SkyViewRow(zenith, table);
  float phi = 0.0;
  if (dot(w.xy, w.xy) > 0.0)
  {
    phi = atan(w.x, w.y) - sunAzimuth;
    phi = abs(mod(phi + kPi, 2.0 * kPi) - kPi);
  }
  float column = clamp(phi / kPi, 0.0, 1.0) * (table.y - 1.0);
  return vec2(column, row);
}

// Texture coordinates of direction w in a table of that layout.
vec2 SkyViewUv(vec3 w, vec4 table)
{
  vec2 texel = SkyViewTexel(w, sunAzimuthRadians, table);
  return vec2((texel.x + 0.5) / table.y, (texel.y + 0.5) / (table.z + table.w));
}

// Sky radiance (linear sRGB, relative to the sun, no exposure) along unit w,
// with the sun disc when it is on.
vec3 SkyRadiance(vec3 w)
{
  vec2 uv = SkyViewUv(w, skyTable);
  float nu = dot(w, sunDirection);
  vec3 L = Rayleigh(nu) * texture(skyRayleigh, uv).rgb +
    CornetteShanks(nu, mieG) * texture(skyMie, uv).rgb + texture(skyIsotropic, uv).rgb;
  if (sunDisc != 0)
  {
    float angle = acos(clamp(nu, -1.0, 1.0));
    if (angle < sunAngularRadius)
    {
      // Limb darkening I(mu) = 1 - u (1 - mu), u = 0.6, normalised to the disc mean 1 - u/3.
      float q = angle / sunAngularRadius;
      float mu = sqrt(max(0.0, 1.0 - q * q));
      L += sunDiscRadiance * (1.0 - 0.6 * (1.0 - mu)) / (1.0 - 0.2);
    }
  }
  return L;
}
