// Sampling-interval and Mie-scattering textures (000 §4.4) in one RGBA target:
// r = 1/|v.n| (Delta t(p) = Delta d / |v.n|), g = beta_cl(alpha) + k_multi/(4 pi),
// b = Rayleigh phase, a = haze (Mie) phase, for the view ray of each pixel.
// Phase functions are nimbusPhase.glsl's (Cornette-Shanks normalised to 1 over the
// sphere [1/sr]: 000 Eq. 3 divided by 4 pi); cos(alpha) = dot(v, L).
in vec2 texCoord;
uniform float cloudG;
uniform float mieG;
uniform float multipleScattering; // k_multi (000 Eq. 1), dimensionless

void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  float vn = abs(dot(direction, sliceNormal));
  float mu = clamp(dot(direction, sunDirection), -1.0, 1.0);
  gl_FragData[0] = vec4(1.0 / max(vn, 1e-6),
    CornetteShanks(mu, cloudG) + multipleScattering / (4.0 * kPi), Rayleigh(mu),
    CornetteShanks(mu, mieG));
}
