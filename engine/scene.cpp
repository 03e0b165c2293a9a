// Placeholder until the scene loader lands.
#include "engine/scene.h"
