//! Assembly, Newton iterations, generalized-alpha time integration, static and modal analyses.
