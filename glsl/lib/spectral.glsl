// spectral.glsl — wavelength-dependent index of refraction and the camera's channel sensitivities.
// Wavelengths in nanometres. Used only when the scene has KHR_materials_dispersion.

const float kLambdaMin = 380.0;  // nm
const float kLambdaMax = 780.0;  // nm
// Channel sensitivities: Gaussians (mean, sigma in nm) whose integral over [380, 780] nm is 1 (tails
// beyond the range are below 2e-4). RGB mode traces each channel at its mean wavelength.
const vec3 kChannelLambda = vec3(610.0, 545.0, 460.0);
const vec3 kChannelSigma = vec3(30.0, 30.0, 22.0);

// W_c(lambda) per nm; integral over the visible range is 1 for each channel.
vec3 channelSensitivity(float lambda) {
  vec3 x = (vec3(lambda) - kChannelLambda) / kChannelSigma;
  return exp(-0.5 * x * x) / (kChannelSigma * 2.50662827463);
}

// Cauchy fit n(lambda) = A + B / lambda^2 through the index at the d line (587.6 nm) and the Abbe
// number V = (n_d - 1) / (n_F - n_C), as KHR_materials_dispersion prescribes. abbe <= 0: no dispersion.
float cauchyIor(float iorD, float abbe, float lambdaNm) {
  if (abbe <= 0.0) return iorD;
  const float lF = 486.1, lC = 656.3, lD = 587.6;
  float b = (iorD - 1.0) / (abbe * (1.0 / (lF * lF) - 1.0 / (lC * lC)));
  float a = iorD - b / (lD * lD);
  return a + b / (lambdaNm * lambdaNm);
}

// The wavelength a path keeps from its first dispersive event on, chosen with u uniform in [0, 1), and
// its per-channel weight: a hero wavelength uniform over the visible range weighted by the channel
// sensitivities (CAUSTICA_SPECTRAL), or one RGB channel at its mean wavelength weighted 3.
void pickWavelength(float u, out float lambda, out vec3 filt) {
#ifdef CAUSTICA_SPECTRAL
  lambda = kLambdaMin + (kLambdaMax - kLambdaMin) * u;
  filt = channelSensitivity(lambda) * (kLambdaMax - kLambdaMin);
#else
  int c = min(int(u * 3.0), 2);
  lambda = kChannelLambda[c];
  filt = vec3(0.0);
  filt[c] = 3.0;
#endif
}
