//! Classification (SPEC 3.12-3.13): k-nearest neighbours with training-fold z-scoring,
//! stratified shuffled k-fold cross-validation and train/test evaluation.

pub mod cv;
pub mod knn;

pub use cv::{
    confusion_matrix, cross_validate, stratified_folds, train_test, CvParams, CvResult, Evaluation,
};
pub use knn::{Knn, KnnModel, KnnParams};
