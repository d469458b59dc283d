// The sky-view table lookup shared by the sky pass and the sky background
// (vtkNimbusSkyPass, vtkNimbusSkyBackground): GPU twin of nimbus::SkyViewLut::Radiance
// (Physics/Sky.cxx — same row/column maps, same phase functions) plus the
// limb-darkened sun disc and the sRGB transfer functions. Uniforms are set by
// nimbus::SkyViewTextures (SkyViewGL.cxx).
//
// L = p_R(nu) A_R + p_M(nu) A_M + A_I  (Sky.h), nu = dot(view, sun).
uniform sampler2D skyRayleigh;
uniform sampler2D skyMie;
uniform sampler2D skyIsotropic;
uniform vec3 sunDirection;          // unit, scene frame (z up)
uniform float sunAzimuth;           // rad, from +y toward +x
uniform float mieG;
uniform vec3 displayScale;          // exposure / sun colour, per channel
uniform vec4 skyTable;    // horizon zenith (rad), width, rows above, rows below
uniform int sunDisc;
uniform vec3 sunDiscRadiance;
uniform float sunRadius; // rad

const float PI = 3.14159265358979;

float rayleighPhase(float nu)
{
  return 3.0 / (16.0 * PI) * (1.0 + nu * nu);
}

// Cornette-Shanks (000 Eq. 3), divided by 4 pi; denominator written as (1-g)^2 + 2g(1-nu).
float miePhase(float nu)
{
  float g = mieG;
  float d = (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - nu);
  return 3.0 * (1.0 - g * g) / (2.0 * (2.0 + g * g)) * (1.0 + nu * nu) / (d * sqrt(d)) / (4.0 * PI);
}

// SkyViewMapping::Row: rows [0, above-1] from the horizon up (zenith th (1 - s^3)),
// rows [above, above+below-1] from the horizon down (th + s^3 (pi - th)).
float tableRow(float zenith, vec4 table)
{
  float th = table.x;
  if (zenith <= th)
  {
    float a = clamp((th - zenith) / th, 0.0, 1.0);
    return pow(a, 1.0 / 3.0) * (table.z - 1.0);
  }
  float b = clamp((zenith - th) / (PI - th), 0.0, 1.0);
  return table.z + pow(b, 1.0 / 3.0) * (table.w - 1.0);
}

// Texture coordinates of direction w: column = azimuth from the sun in [0, pi].
vec2 tableUv(vec3 w, vec4 table)
{
  float zenith = acos(clamp(w.z, -1.0, 1.0));
  float row = tableRow(zenith, table);
  float phi = 0.0;
  if (dot(w.xy, w.xy) > 0.0)
  {
    phi = atan(w.x, w.y) - sunAzimuth;
    phi = abs(mod(phi + PI, 2.0 * PI) - PI);
  }
  float col = clamp(phi / PI, 0.0, 1.0) * (table.y - 1.0);
  return vec2((col + 0.5) / table.y, (row + 0.5) / (table.z + table.w));
}

float srgbEncode(float c)
{
  c = clamp(c, 0.0, 1.0);
  return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

float srgbDecode(float c)
{
  return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

vec3 encode(vec3 c)
{
  return vec3(srgbEncode(c.r), srgbEncode(c.g), srgbEncode(c.b));
}

vec3 decode(vec3 c)
{
  return vec3(srgbDecode(c.r), srgbDecode(c.g), srgbDecode(c.b));
}

// Sky radiance (linear sRGB, relative to the sun, no exposure) along unit w,
// with the sun disc when it is on.
vec3 SkyRadiance(vec3 w)
{
  vec2 uv = tableUv(w, skyTable);
  float nu = dot(w, sunDirection);
  vec3 L = rayleighPhase(nu) * texture(skyRayleigh, uv).rgb +
    miePhase(nu) * texture(skyMie, uv).rgb + texture(skyIsotropic, uv).rgb;
  if (sunDisc != 0)
  {
    float angle = acos(clamp(nu, -1.0, 1.0));
    if (angle < sunRadius)
    {
      // Limb darkening I(mu) = 1 - u (1 - mu), u = 0.6, normalised to the disc mean 1 - u/3.
      float q = angle / sunRadius;
      float mu = sqrt(max(0.0, 1.0 - q * q));
      L += sunDiscRadiance * (1.0 - 0.6 * (1.0 - mu)) / (1.0 - 0.2);
    }
  }
  return L;
}
