//VTK::System::Dec
// Sky background and aerial perspective (vtkNimbusSkyPass; CPU twin:
// nimbus::SkyViewLut::Radiance and nimbus::AerialPerspectiveLut::Lookup in
// Optics/Sky.cxx — same row/column/slice maps, same phase functions).
//
// L = p_R(nu) A_R + p_M(nu) A_M + A_I  (Sky.h), nu = dot(view, sun).
// Surfaces: colour_out = colour_in * T + DisplayScale * L_inscatter (aerial perspective).
in vec2 texCoord;
//VTK::Output::Dec

uniform sampler2D colorTexture;
uniform sampler2D depthTexture;
uniform sampler2D skyRayleigh;
uniform sampler2D skyMie;
uniform sampler2D skyIsotropic;
uniform sampler3D aerialRayleigh;
uniform sampler3D aerialMie;
uniform sampler3D aerialIsotropic;
uniform sampler3D aerialTransmittance;

uniform mat4 inverseViewProjection; // VTK matrix (row-major): use as vec4 * M
uniform vec3 cameraPosition;        // scene units
uniform float metresPerUnit;
uniform vec3 sunDirection;          // unit, scene frame (z up)
uniform float sunAzimuth;           // rad, from +y toward +x
uniform float mieG;
uniform vec3 displayScale;

uniform vec4 skyTable;    // horizon zenith (rad), width, rows above, rows below
uniform vec4 aerialTable; // horizon zenith (rad), width, rows above, rows below
uniform vec2 aerialSlices; // number of slices, max distance (m)
uniform int aerialPerspective;
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

vec3 unproject(float ndcZ)
{
  vec4 p = vec4(texCoord * 2.0 - 1.0, ndcZ, 1.0) * inverseViewProjection;
  return p.xyz / p.w;
}

void main()
{
  vec4 color = texture(colorTexture, texCoord);
  float depth = texture(depthTexture, texCoord).r;
  gl_FragDepth = depth;
  if (depth >= 1.0)
  {
    vec3 w = normalize(unproject(1.0) - cameraPosition);
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
    // Translucent props drawn here (no depth) are composited over the sky
    // (premultiplied colour, coverage in alpha).
    gl_FragData[0] = vec4(encode(decode(color.rgb) + (1.0 - color.a) * L * displayScale), 1.0);
    return;
  }
  if (aerialPerspective == 0)
  {
    gl_FragData[0] = color;
    return;
  }
  vec3 d = unproject(depth * 2.0 - 1.0) - cameraPosition;
  float len = length(d);
  if (!(len > 0.0))
  {
    gl_FragData[0] = color;
    return;
  }
  vec3 w = d / len;
  float distance = len * metresPerUnit;
  vec2 uv = tableUv(w, aerialTable);
  // Slices at D (k/(S-1))^2, linear in the distance between two slices (as the CPU twin).
  float S = aerialSlices.x, D = aerialSlices.y;
  float u = sqrt(clamp(distance / D, 0.0, 1.0)) * (S - 1.0);
  float k0 = min(floor(u), S - 2.0);
  float d0 = D * (k0 / (S - 1.0)) * (k0 / (S - 1.0));
  float d1 = D * ((k0 + 1.0) / (S - 1.0)) * ((k0 + 1.0) / (S - 1.0));
  float fk = clamp((min(distance, D) - d0) / (d1 - d0), 0.0, 1.0);
  vec3 uvw = vec3(uv, (k0 + fk + 0.5) / S);
  float nu = dot(w, sunDirection);
  vec3 inscatter = rayleighPhase(nu) * texture(aerialRayleigh, uvw).rgb +
    miePhase(nu) * texture(aerialMie, uvw).rgb + texture(aerialIsotropic, uvw).rgb;
  vec3 T = texture(aerialTransmittance, uvw).rgb;
  vec3 surface = decode(color.rgb);
  gl_FragData[0] = vec4(encode(surface * T + inscatter * displayScale), color.a);
}
